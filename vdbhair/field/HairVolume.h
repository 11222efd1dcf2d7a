/// @file HairVolume.h
/// @brief The volume a hairstyle occupies, as refinement holds strands in it and the measures
/// judge strands against it (spikes and flares: countStrandsLeavingVolume()): the voxels of a
/// field's active region (the voxels its strands' segments pass), or of a hairstyle's points,
/// dilated by one voxel (26 neighbours). A world point is inside when the voxel nearest to it is
/// (world / voxel rounded); a polyline when its vertices and points at most half a voxel apart
/// between them are.
#pragma once

#include <vdbhair/SegmentWalk.h>
#include <vdbhair/Types.h>
#include <vdbhair/field/FieldMapping.h>
#include <vdbhair/strands/StrandSet.h>

#include <openvdb/openvdb.h>

#include <algorithm>
#include <cstddef>

namespace vdbhair {

class HairVolume
{
public:
    /// @brief The active region of @a grid (a tangent field's), dilated by one voxel.
    explicit HairVolume(const openvdb::Vec3SGrid& grid);
    /// @brief The voxels of side @a voxel (world origin) of the points of @a reference (each
    /// strand's vertices and points at most half a voxel apart between them), dilated by one voxel.
    /// In parallel; the same for any thread count.
    /// @throw ValueError for a voxel that is not positive and finite, one so small that the hair
    /// spans over 2^19 voxels from the origin, or a segment would take over 2^24 points.
    HairVolume(const StrandSet& reference, double voxel, bool threaded = true);

    const FieldMapping& mapping() const { return mMap; }

    /// @brief Point queries; one per thread.
    class Probe
    {
    public:
        explicit Probe(const HairVolume& v) : mV(v), mAcc(v.mTree) {}
        bool contains(const Vec3d& world)
        {
            const openvdb::Coord ijk = nearestVoxel(mV.mMap.worldToIndex(world));
            if (ijk == mLastInside) return true;  // points along a strand: often the same voxel
            if (!mAcc.isValueOn(ijk)) return false;
            mLastInside = ijk;
            return true;
        }
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
        /// The points of segment (a, b) at most half a voxel apart, b included, a not.
        bool containsSegment(const Vec3d& a, const Vec3d& b, double half);

        const HairVolume& mV;
        openvdb::tree::ValueAccessor<const openvdb::BoolTree> mAcc;
        openvdb::Coord mLastInside = openvdb::Coord::max();  ///< nearestVoxel() never gives it
    };

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

    FieldMapping mMap;
    openvdb::BoolTree mTree;
};

/// @brief The number of @a strands that leave the hair volume of @a reference at @a voxel
/// (HairVolume(reference, voxel)): the guides issue's measure of spikes and flares. In parallel;
/// identical for any thread count.
/// @throw ValueError as HairVolume(), for either hairstyle.
std::size_t countStrandsLeavingVolume(const StrandSet& strands, const StrandSet& reference, double voxel, bool threaded = true);

} // namespace vdbhair
