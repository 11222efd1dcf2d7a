/// @file RootGrid.h
/// @brief Roots as OpenVDB points: a PointDataGrid named `roots` with `P`, `N` (unit normal,
/// Houdini's name), `tangent` (the frame's tangent) and a `root` group holding every point, so
/// that Houdini and Blender open it as a point cloud with normals.
#pragma once

#include <vdbhair/io/PointFile.h>

#include <openvdb/points/PointDataGrid.h>

#include <string>

namespace vdbhair {

/// @param pointsPerVoxel the grid's voxel size is chosen for about this many points per voxel
/// @throw ValueError (no points, normals or tangents of the wrong size).
openvdb::points::PointDataGrid::Ptr createRootGrid(const OrientedPoints& roots, unsigned pointsPerVoxel = 8);

} // namespace vdbhair
