/// @file SurfaceCells.h
/// @brief Where sampleFollicles() can put roots (Follicles.h, steps 1 and 3): the band voxels of a
/// scalp's zero level set with their shares of its area, and the region's contour on the surface
/// as fixed particles.
#pragma once

#include <vdbhair/Types.h>
#include <vdbhair/scalp/Follicles.h>
#include <vdbhair/scalp/ScalpSampler.h>

#include <openvdb/openvdb.h>
#include <openvdb/util/NullInterrupter.h>

#include <vector>

namespace vdbhair {

/// A band voxel of the zero level set and its share of the area.
struct SurfaceCell { openvdb::Coord ijk; double weight; };

/// The area of the zero level set in the sampler's region, and its band voxels with their weights
/// (@a cells, when given): only voxels within two voxels of a sign change. A band with no zero in
/// it (both sides positive: an open part of a mesh that capping did not close, e.g. head_max4's
/// torso) has no surface to project onto; counting its area put the roots it was owed on the rest,
/// at half the spacing (measured: CV 0.52, median spacing 0.51 of the target, on head_max4 at
/// 0.5-unit voxels). Its area is returned apart, as areaWithoutZero.
ScalpArea surfaceCells(const openvdb::FloatGrid& surface, const ScalpSampler& sampler, std::vector<SurfaceCell>* cells);

/// The region's contour on the surface, as fixed particles about @a spacing apart. Every pair of
/// face neighbours (a in the region, b out of it, both on the surface's band near zero) gives a
/// rim point: the segment between their projections onto the zero level set is bisected (12
/// times, each midpoint projected) to where the region ends, keeping the last point inside. The
/// points are walked as nearest-neighbour chains (next: the nearest unvisited point within two
/// voxels) and a point is kept when it is at least @a spacing from every point kept before, so
/// along a rim the kept points are @a spacing to @a spacing plus a voxel apart. Serial order
/// throughout: the same points for any thread count.
std::vector<Vec3d> contourParticles(const openvdb::FloatGrid& surface, const ScalpSampler& sampler, const std::vector<SurfaceCell>& cells,
                                    double spacing, bool threaded, openvdb::util::NullInterrupter* interrupter);

} // namespace vdbhair
