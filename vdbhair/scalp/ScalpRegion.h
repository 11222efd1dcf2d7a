/// @file ScalpRegion.h
/// @brief Where on the scalp hair grows (DESIGN.md, grid `region`): a BoolGrid on the surface's
/// transform whose active voxels cover the part of the narrow band that carries hair.
#pragma once

#include <vdbhair/Types.h>

#include <openvdb/openvdb.h>

#include <vector>

namespace vdbhair {

/// @brief The region "where these strands have roots": each root is projected onto the surface
/// (it usually floats a little above it) and every band voxel within @a radius of the projection
/// becomes active. Named `region`, with `creator` and `vdbhair_region_radius`, `vdbhair_source`.
/// @param roots #R world positions
/// @param radius world units; a voxel is in when its centre is within radius of a projected root
/// @throw ValueError (radius not positive, no roots), LookupError (no root within the band: the
/// region would be empty), LimitError (over @a maxVoxels voxels to visit).
openvdb::BoolGrid::Ptr regionFromRoots(const openvdb::FloatGrid& surface, const std::vector<Vec3f>& roots,
                                       double radius, const std::string& source = "",
                                       std::uint64_t maxVoxels = std::uint64_t(1) << 28);

} // namespace vdbhair
