/// @file PointCloud.h
/// @brief The library's nanoflann dataset adaptors and k-d trees: positions (a vector of Vec3d or
/// Vec3f: follicle repulsion, regions from roots, guide weights, comparisons, root spacing) and
/// rows of a flat array whose dimension is known only at run time (texture synthesis's
/// feature-space keys).
#pragma once

#include <vdbhair/Types.h>

#include <nanoflann.hpp>

#include <cstdint>
#include <vector>

namespace vdbhair {

/// @brief A nanoflann dataset adaptor over @a pts, 3D points of type @a VecT (not owned; must
/// outlive the tree). Coordinates and squared distances are of VecT's value type.
template<class VecT>
struct PointCloudOf
{
    using ValueType = typename VecT::value_type;
    const std::vector<VecT>* pts;
    std::size_t kdtree_get_point_count() const { return pts->size(); }
    ValueType kdtree_get_pt(std::size_t i, std::size_t d) const { return (*pts)[i][int(d)]; }
    template<class BBoxT> bool kdtree_get_bbox(BBoxT&) const { return false; }
};

/// @brief A 3D k-d tree over a PointCloudOf<VecT> (indices 32-bit).
template<class VecT>
using PointKdTreeOf = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<typename VecT::value_type, PointCloudOf<VecT>>,
                                                          PointCloudOf<VecT>, 3, std::uint32_t>;

/// @brief The adaptor and the tree over world positions in double precision.
using PointCloud = PointCloudOf<Vec3d>;
using PointKdTree = PointKdTreeOf<Vec3d>;

/// @brief A nanoflann dataset adaptor over @a count rows of @a dim floats each, row-major at @a pts
/// (not owned; must outlive the tree): points whose dimension is chosen at run time.
struct RowCloud
{
    const float* pts = nullptr;
    std::size_t count = 0;
    int dim = 0;
    std::size_t kdtree_get_point_count() const { return count; }
    float kdtree_get_pt(std::size_t i, std::size_t d) const { return pts[i * std::size_t(dim) + d]; }
    template<class BBoxT> bool kdtree_get_bbox(BBoxT&) const { return false; }
};

/// @brief A k-d tree over a RowCloud, of the dimension given to its constructor (indices 32-bit).
/// L2_Adaptor, not L2_Simple_Adaptor: in many dimensions it stops summing a distance once it
/// passes the worst neighbour kept.
using RowKdTree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Adaptor<float, RowCloud, float>, RowCloud, -1, std::uint32_t>;

} // namespace vdbhair
