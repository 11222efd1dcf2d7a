/// @file SegmentWalk.h
/// @brief Visit every voxel a straight segment passes through (a 3D DDA, Amanatides & Woo 1987),
/// with the part of the segment inside each voxel.
#pragma once

#include <openvdb/Types.h>  // openvdb::Vec3d, openvdb::Coord

#include <cmath>
#include <cstdint>
#include <limits>

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
/// @return the number of voxels visited.
template<typename Fn>
inline std::uint64_t walkSegment(const openvdb::Vec3d& a, const openvdb::Vec3d& b, Fn&& fn)
{
    const openvdb::Vec3d d = b - a;
    openvdb::Coord ijk(floorToInt(a.x() + 0.5), floorToInt(a.y() + 0.5), floorToInt(a.z() + 0.5));
    const openvdb::Coord last(floorToInt(b.x() + 0.5), floorToInt(b.y() + 0.5), floorToInt(b.z() + 0.5));
    if (ijk == last) {  // the common case for segments shorter than a voxel
        fn(ijk, 0.0, 1.0);
        return 1;
    }
    int step[3];
    double tMax[3], tDelta[3];
    constexpr double inf = std::numeric_limits<double>::infinity();
    for (int k = 0; k < 3; ++k) {
        if (d[k] > 0.0) {
            step[k] = 1;
            tDelta[k] = 1.0 / d[k];
            tMax[k] = (double(ijk[k]) + 0.5 - a[k]) * tDelta[k];
        } else if (d[k] < 0.0) {
            step[k] = -1;
            tDelta[k] = -1.0 / d[k];
            tMax[k] = (a[k] - double(ijk[k]) + 0.5) * tDelta[k];
        } else {
            step[k] = 0;
            tMax[k] = inf;
            tDelta[k] = inf;
        }
    }
    // At most one voxel per crossed boundary plus the first: a hard bound against rounding loops.
    const std::uint64_t maxVisits = std::uint64_t(std::abs(last.x() - ijk.x())) +
                                    std::uint64_t(std::abs(last.y() - ijk.y())) +
                                    std::uint64_t(std::abs(last.z() - ijk.z())) + 1;
    double t = 0.0;
    std::uint64_t visits = 0;
    while (true) {
        const int axis = (tMax[0] < tMax[1]) ? (tMax[0] < tMax[2] ? 0 : 2) : (tMax[1] < tMax[2] ? 1 : 2);
        const double tNext = tMax[axis];
        if (tNext >= 1.0 || visits + 1 >= maxVisits) {
            if (1.0 > t) fn(ijk, t, 1.0);
            return visits + 1;
        }
        if (tNext > t) {
            fn(ijk, t, tNext);
            t = tNext;
        }
        ijk[axis] += step[axis];
        tMax[axis] += tDelta[axis];
        ++visits;
    }
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
