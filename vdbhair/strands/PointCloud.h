/// @file PointCloud.h
/// @brief nanoflann's view of a vector of world positions, and the k-d tree over it that the
/// neighbour searches share (follicle repulsion, regions from roots, guide weights, comparisons).
#pragma once

#include <vdbhair/Types.h>

#include <nanoflann.hpp>

#include <cstdint>
#include <vector>

namespace vdbhair {

/// @brief A nanoflann dataset adaptor over @a pts (not owned; must outlive the tree).
struct PointCloud
{
    const std::vector<Vec3d>* pts;
    std::size_t kdtree_get_point_count() const { return pts->size(); }
    double kdtree_get_pt(std::size_t i, std::size_t d) const { return (*pts)[i][int(d)]; }
    template<class BBoxT> bool kdtree_get_bbox(BBoxT&) const { return false; }
};

/// @brief A 3D k-d tree over a PointCloud (indices 32-bit).
using PointKdTree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, PointCloud>, PointCloud, 3, std::uint32_t>;

} // namespace vdbhair
