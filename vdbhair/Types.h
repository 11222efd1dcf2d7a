/// @file Types.h
/// @brief The shared vocabulary of vdbhair: vectors, frames and boxes in world units.
#pragma once

#include <openvdb/math/Vec2.h>
#include <openvdb/math/Vec3.h>

#include <cstdint>
#include <limits>

namespace vdbhair {

/// Strand code uses one float type (world units) and no templates.
using Vec3f = openvdb::math::Vec3<float>;
using Vec3d = openvdb::math::Vec3<double>;
using Vec2f = openvdb::math::Vec2<float>;

/// @brief An orthonormal frame along a curve: unit tangent, normal and binormal (b = t x n).
struct Frame
{
    Vec3f t{1.f, 0.f, 0.f};
    Vec3f n{0.f, 1.f, 0.f};
    Vec3f b{0.f, 0.f, 1.f};
};

/// @brief An axis-aligned box in world units; empty until a point is added.
struct BBox
{
    Vec3f min{std::numeric_limits<float>::max()};
    Vec3f max{-std::numeric_limits<float>::max()};

    bool empty() const { return min.x() > max.x(); }
    void expand(const Vec3f& p)
    {
        min = openvdb::math::minComponent(min, p);
        max = openvdb::math::maxComponent(max, p);
    }
    Vec3f extent() const { return empty() ? Vec3f(0.f) : max - min; }
};

} // namespace vdbhair
