/// @file ScalpRegion.h
/// @brief Where on the scalp hair grows (DESIGN.md, grid `region`): a BoolGrid on the surface's
/// transform whose active voxels cover the part of the narrow band that carries hair.
#pragma once

#include <vdbhair/Types.h>

#include <openvdb/openvdb.h>

#include <limits>
#include <string>
#include <vector>

namespace vdbhair {

/// @brief The closest points of the zero level set to @a points, which may lie anywhere (roots
/// usually float a few voxels above the scalp, outside its narrow band): from the nearest voxel the
/// zero level set crosses (a k-d tree of them), Newton steps along the gradient (ScalpSampler).
/// @return #P world positions; @a onSurface (if not null) says which reached |phi| < 0.5 voxel.
std::vector<Vec3f> projectOntoSurface(const openvdb::FloatGrid& surface, const std::vector<Vec3f>& points,
                                      std::vector<char>* onSurface = nullptr);

/// @brief The region "where these strands have roots": each root is projected onto the surface
/// (projectOntoSurface()) and every band voxel within @a radius of the projection becomes active. Named `region`, with `creator` and `vdbhair_region_radius`, `vdbhair_source`.
/// @param roots #R world positions
/// @param radius world units; a voxel is in when its centre is within radius of a projected root
/// @param maxDistance roots farther than this from the surface (world units) are left out
/// @throw ValueError (radius not positive, no roots), LookupError (no root within maxDistance:
/// the region would be empty), LimitError (over @a maxVoxels voxels to visit).
openvdb::BoolGrid::Ptr regionFromRoots(const openvdb::FloatGrid& surface, const std::vector<Vec3f>& roots,
                                       double radius, const std::string& source = "",
                                       std::uint64_t maxVoxels = std::uint64_t(1) << 28,
                                       double maxDistance = std::numeric_limits<double>::max());

/// @brief The region from a mask grid: the surface's band voxels whose centre the mask covers. A
/// @brief regionFromMask()'s default threshold: a float mask covers where it exceeds one half.
constexpr double kDefaultMaskThreshold = 0.5;

/// BoolGrid covers where it is true (active or not: the value is what counts; its background too);
/// a FloatGrid where its trilinear value exceeds @a threshold (a painted weight, a fog volume). The
/// mask may have any transform (sampled at world positions). Named `region`, with `creator`,
/// `vdbhair_region_kind` "mask", `vdbhair_region_threshold` and `vdbhair_source`.
/// @throw TypeError (neither a BoolGrid nor a FloatGrid), ValueError (a non-finite threshold),
/// LookupError (the mask covers no surface voxel: the region would be empty).
openvdb::BoolGrid::Ptr regionFromMask(const openvdb::FloatGrid& surface, const openvdb::GridBase& mask, double threshold = kDefaultMaskThreshold,
                                      const std::string& source = "");

} // namespace vdbhair
