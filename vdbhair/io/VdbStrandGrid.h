/// @file VdbStrandGrid.h
/// @brief Grid-level conversion between strands and OpenVDB points, for code that puts strands
/// in a file with other grids (see VdbStrands.h for the layout).
#pragma once

#include <vdbhair/io/VdbStrands.h>

#include <openvdb/points/PointDataGrid.h>

namespace vdbhair {

/// @brief The `strands` PointDataGrid of @a strands (named "strands", metadata set).
/// @param where message prefix
/// @throw ValueError if the set is empty or the voxel size is not positive and finite.
openvdb::points::PointDataGrid::Ptr createStrandGrid(const StrandSet& strands,
                                                     const VdbPointsOptions& opts = {},
                                                     const std::string& where = "createStrandGrid");

/// @brief openvdb::points::computeVoxelSize(@a positions, @a pointsPerVoxel) (its identity
/// transform and 5 decimals), the same value, faster: each of its rounds counts the voxels that
/// hold a point by setting them in a mask tree, a third of writing a strands grid; here they are
/// counted with a bit per voxel of the points' box (in parallel), where that box has at most
/// 2^30 voxels, and in OpenVDB's mask beyond.
/// @throw ValueError if @a pointsPerVoxel is 0.
float pointsVoxelSize(const std::vector<Vec3f>& positions, unsigned pointsPerVoxel);

/// @brief Strands from a PointDataGrid in the vdbhair layout.
/// @param where message prefix, e.g. "readVdbStrands(a.vdb)"
/// @throw FormatError naming the rule broken (missing attribute, duplicate or missing vertex).
StrandSet strandsFromGrid(const openvdb::points::PointDataGrid& grid, const std::string& where,
                          const ReadOptions& opts = {}, ReadReport* report = nullptr);

} // namespace vdbhair
