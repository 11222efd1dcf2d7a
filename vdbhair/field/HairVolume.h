/// @file HairVolume.h
/// @brief The volume a hairstyle occupies, as refinement holds strands in it and measures them
/// against it: the voxels of a field's active region (the voxels its strands' segments pass),
/// dilated by one voxel (26 neighbours). A world point is inside when the voxel nearest to it is;
/// a polyline when its vertices and points at most half a voxel apart between them are.
#pragma once

#include <vdbhair/Types.h>
#include <vdbhair/field/FieldMapping.h>
#include <vdbhair/field/SegmentWalk.h>

#include <openvdb/openvdb.h>

#include <algorithm>
#include <cstddef>

namespace vdbhair {

class HairVolume
{
public:
    /// @brief The active region of @a grid (a tangent field's), dilated by one voxel.
    explicit HairVolume(const openvdb::Vec3SGrid& grid);

    const FieldMapping& mapping() const { return mMap; }

    /// @brief Point queries; one per thread.
    class Probe
    {
    public:
        explicit Probe(const HairVolume& v) : mV(v), mAcc(v.mTree) {}
        bool contains(const Vec3d& world) { return mAcc.isValueOn(nearestVoxel(mV.mMap.worldToIndex(world))); }
        /// @brief Whether the vertices of @a p (n of them) and points at most half a voxel apart
        /// between them are all inside.
        bool containsPolyline(const Vec3f* p, std::size_t n);
        /// @brief containsPolyline(@a p, @a n) over the parts of @a p that differ from @a ref
        /// (also n vertices): its first vertex if that differs, and each segment one of whose
        /// vertices differs. The segments @a p shares with @a ref are not tested, so when this
        /// is true and @a p is not inside, neither is @a ref (a retraced strand that leaves the
        /// volume only where its input does is not the retrace's doing).
        bool containsChanged(const Vec3f* p, const Vec3f* ref, std::size_t n);

    private:
        /// openvdb::Coord::round(@a p) without a call to floor() per axis (voxelOf()); positions
        /// beyond ±2^30 (or NaN), where no voxel of a field is, clamp there first.
        static openvdb::Coord nearestVoxel(const Vec3d& p)
        {
            auto clamp = [](double x) {
                constexpr double kLimit = double(1 << 30);
                return std::min(kLimit, std::max(-kLimit, x));  // this order maps NaN to -kLimit
            };
            return voxelOf(Vec3d(clamp(p.x()), clamp(p.y()), clamp(p.z())));
        }

        /// The points of segment (a, b) at most half a voxel apart, b included, a not.
        bool containsSegment(const Vec3d& a, const Vec3d& b, double half);

        const HairVolume& mV;
        openvdb::tree::ValueAccessor<const openvdb::BoolTree> mAcc;
    };

private:
    FieldMapping mMap;
    openvdb::BoolTree mTree;
};

} // namespace vdbhair
