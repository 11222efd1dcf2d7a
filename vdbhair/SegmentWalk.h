/// @file SegmentWalk.h
/// @brief Visit every voxel a straight segment passes through (a 3D DDA, Amanatides & Woo 1987),
/// with the part of the segment inside each voxel.
#pragma once

#include <openvdb/Types.h>  // openvdb::Vec3d, openvdb::Coord

#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>
#include <algorithm>

namespace vdbhair {

/// @brief floor(x) as an int, without a libm call (|x| < 2^31; callers check the index range).
inline int floorToInt(double x)
{
    const int i = int(x);
    return i - int(x < double(i));
}

/// @brief Walk the segment from @a a to @a b (index space: voxel ijk spans [ijk - 0.5, ijk + 0.5)
/// on each axis, OpenVDB's cell-centred convention) and call `fn(ijk, t0, t1)` for every voxel it
/// passes through, in order, where [t0, t1] ⊂ [0, 1] is the segment parameter range inside it.
/// Pieces of zero length (exact corner crossings) are skipped.
///
/// A 3D DDA restricted to the axes whose voxel coordinate changes: each such axis crosses exactly
/// |Δ| voxel boundaries, so the walk takes exactly that many steps and ends in @a last whatever
/// the rounding (the crossing parameters are clamped to stay monotone in [0, 1]). This is the walk
/// the tangent field's estimate ships (TangentField.cc).
/// @param first, last the voxels of @a a and @a b (voxelOf() below), which the caller often has
/// @return the number of voxels stepped through (|Δx| + |Δy| + |Δz| + 1).
template<typename Fn>
inline std::uint64_t walkSegment(const openvdb::Vec3d& a, const openvdb::Vec3d& b, openvdb::Coord first,
                                 const openvdb::Coord& last, Fn&& fn)
{
    constexpr double inf = std::numeric_limits<double>::infinity();
    openvdb::Coord& ijk = first;
    int step[3], left[3];
    double tMax[3], tDelta[3];
    int total = 0;
    for (int k = 0; k < 3; ++k) {
        const int n = last[k] - ijk[k];
        left[k] = std::abs(n);
        total += left[k];
        if (n == 0) {
            step[k] = 0;
            tMax[k] = tDelta[k] = inf;
        } else {
            // The boundary on the way out of the first voxel, and the next ones 1 / |d| apart.
            const double inv = 1.0 / (b[k] - a[k]);
            step[k] = n > 0 ? 1 : -1;
            tDelta[k] = std::abs(inv);
            tMax[k] = (double(ijk[k]) + 0.5 * double(step[k]) - a[k]) * inv;
        }
    }
    double t = 0.0;
    for (int s = 0; s < total; ++s) {
        const int axis = (tMax[0] < tMax[1]) ? (tMax[0] < tMax[2] ? 0 : 2) : (tMax[1] < tMax[2] ? 1 : 2);
        const double tNext = std::min(std::max(tMax[axis], t), 1.0);  // monotone despite rounding
        if (tNext > t) fn(static_cast<const openvdb::Coord&>(ijk), t, tNext);
        t = tNext;
        ijk[axis] += step[axis];
        tMax[axis] = --left[axis] > 0 ? tMax[axis] + tDelta[axis] : inf;
    }
    if (1.0 > t) fn(static_cast<const openvdb::Coord&>(ijk), t, 1.0);
    return std::uint64_t(total) + 1;
}

/// @brief The voxel holding index position @a p (voxel ijk spans [ijk - 0.5, ijk + 0.5)).
inline openvdb::Coord voxelOf(const openvdb::Vec3d& p)
{
    return openvdb::Coord(floorToInt(p.x() + 0.5), floorToInt(p.y() + 0.5), floorToInt(p.z() + 0.5));
}

/// @brief walkSegment() with the voxels of @a a and @a b found here.
template<typename Fn>
inline std::uint64_t walkSegment(const openvdb::Vec3d& a, const openvdb::Vec3d& b, Fn&& fn)
{
    return walkSegment(a, b, voxelOf(a), voxelOf(b), std::forward<Fn>(fn));
}

/// @brief An upper bound on the voxels walkSegment() visits, cheap enough to compute for every
/// segment before any allocation: the first voxel plus at most |Δ| + 1 boundary crossings per axis.
inline std::uint64_t segmentVoxelBound(const openvdb::Vec3d& a, const openvdb::Vec3d& b)
{
    const double n = 4.0 + std::abs(b.x() - a.x()) + std::abs(b.y() - a.y()) + std::abs(b.z() - a.z());
    // Saturate (callers compare to a cap); below 1e18 the signed conversion, a single instruction
    // on x86-64 where the unsigned one is a branchy sequence, gives the same value.
    return n < 1e18 ? std::uint64_t(std::int64_t(n)) : std::uint64_t(1e18);
}

} // namespace vdbhair
