/// @file PointInterpolation.h
/// @brief The peers' way of filling in hair between guides, as a baseline for helicoid
/// interpolation: blend the guides' *points* (Blender 3.5's Interpolate Curves node; Houdini's
/// Hair Generate does the same).
///
/// For a new root x̃: the K nearest guides by root (K = 4, Blender's default) weighted as in
/// GuideLocator::fadedWeights() (the farthest of K + 1 faded to zero, so guides enter and leave
/// without popping); the new strand has round(Σ w_i n_i) vertices (n_i the guides' counts, at least
/// 2); each guide is resampled by arc length to that count, taken as offsets from its root, rotated
/// from the guide root's frame to the new root's (with normals: the smallest rotation taking the
/// guide root's normal to the new root's, as Blender's "up" vectors; without: no rotation), and
/// the weighted offsets are added to x̃.
#pragma once

#include <vdbhair/helicoid/HelicoidInterpolation.h>
#include <vdbhair/strands/StrandSet.h>

#include <openvdb/util/NullInterrupter.h>

namespace vdbhair {

struct PointInterpolationParams
{
    int neighbors = 4;  ///< K nearest guides (Blender's "Max Neighbors" default), K >= 1
    std::size_t maxVertices = std::size_t(1) << 28;  ///< as HelicoidInterpolationParams
};

/// @brief New strands at every root by blending the points of @a guides (see above). In parallel,
/// identical for any thread count.
/// @param guideNormals empty or #G unit normals at the guide roots; with root normals and no guide
/// normals, each guide takes the normal of the root nearest it (as interpolateHelicoids()).
/// @throw ValueError (no guides, a guide of zero length or with non-finite points, no roots, bad
/// neighbors, normals of the wrong size), LimitError (estimated before any work), InterruptedError.
StrandSet interpolatePoints(const StrandSet& guides, const InterpolationRoots& roots, const PointInterpolationParams& params,
                            const std::vector<Vec3d>& guideNormals = {}, bool threaded = true,
                            openvdb::util::NullInterrupter* interrupter = nullptr);

/// @brief interpolatePoints() from a guide scene: its guides grown without their wisps (growScene()).
/// @throw as growScene() and interpolatePoints().
StrandSet interpolatePoints(const Scene& guides, const InterpolationRoots& roots, const PointInterpolationParams& params,
                            const std::vector<Vec3d>& guideNormals = {}, bool threaded = true,
                            openvdb::util::NullInterrupter* interrupter = nullptr);

} // namespace vdbhair
