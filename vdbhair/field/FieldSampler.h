/// @file FieldSampler.h
/// @brief Trilinear sampling of a vector grid at voxel centres, caching the eight corner values of
/// the current cell: streamlines take several steps per cell, so most samples cost no tree access.
///
/// Inactive corners contribute nothing; sample() also returns the summed weight of the active
/// corners, so that callers can tell "outside the field" (no active corner) from "the field
/// vanishes here" (active corners whose vectors cancel).
/// @warning Not thread-safe: one sampler per thread (it owns a ValueAccessor).
#pragma once

#include <openvdb/math/Coord.h>
#include <openvdb/math/Vec3.h>
#include <openvdb/tree/ValueAccessor.h>

#include <cmath>

namespace vdbhair {

template<typename TreeT>
class FieldSampler
{
public:
    using ValueT = typename TreeT::ValueType;
    using LeafT = typename TreeT::LeafNodeType;

    explicit FieldSampler(const TreeT& tree) : mAcc(tree) {}

    /// @brief Sample at index-space position @a p.
    /// @param[out] value the trilinear blend of the active corners' vectors
    /// @return the summed trilinear weight of the active corners (0: outside the field)
    double sample(const openvdb::Vec3d& p, openvdb::Vec3d& value)
    {
        const double fx = std::floor(p.x()), fy = std::floor(p.y()), fz = std::floor(p.z());
        const openvdb::Coord base{int(fx), int(fy), int(fz)};
        if (!mValid || base != mBase) load(base);
        const double u = p.x() - fx, v = p.y() - fy, w = p.z() - fz;
        const double wx[2] = {1.0 - u, u}, wy[2] = {1.0 - v, v}, wz[2] = {1.0 - w, w};
        value = openvdb::Vec3d(0.0);
        double active = 0.0;
        for (int i = 0; i < 8; ++i) {
            const double wt = wx[(i >> 2) & 1] * wy[(i >> 1) & 1] * wz[i & 1];
            value += wt * mValue[i];
            active += wt * mActive[i];
        }
        return active;
    }

    /// @brief Extrapolate beyond the active region: the inverse-square-distance blend of the active
    /// voxels within @a margin voxels of the sampling cell at index position @a p (a box of
    /// (2·margin + 2)³ voxel centres). Called only where sample() found no active corner.
    /// @return the summed weight (0: no active voxel within the margin)
    double extrapolate(const openvdb::Vec3d& p, int margin, openvdb::Vec3d& value)
    {
        const openvdb::Coord base{int(std::floor(p.x())), int(std::floor(p.y())), int(std::floor(p.z()))};
        value = openvdb::Vec3d(0.0);
        double total = 0.0;
        const double reach = double(margin) + 1.0;
        for (int i = -margin; i <= margin + 1; ++i) {
            for (int j = -margin; j <= margin + 1; ++j) {
                for (int k = -margin; k <= margin + 1; ++k) {
                    const openvdb::Coord c = base.offsetBy(i, j, k);
                    ValueT val;
                    if (!mAcc.probeValue(c, val)) continue;
                    const double d2 = (c.asVec3d() - p).lengthSqr();
                    if (d2 > reach * reach) continue;
                    const double w = 1.0 / std::max(d2, 1e-12);
                    value += w * toVec(val);
                    total += w;
                }
            }
        }
        return total;
    }

    /// Number of cells loaded from the tree so far (for statistics).
    std::size_t cellLoads() const { return mLoads; }

private:
    void load(const openvdb::Coord& base)
    {
        mBase = base;
        mValid = true;
        ++mLoads;
        // The 2x2x2 corners lie in one leaf unless the cell straddles a leaf boundary.
        constexpr int mask = int(LeafT::DIM) - 1;
        const bool oneLeaf = (base.x() & mask) != mask && (base.y() & mask) != mask && (base.z() & mask) != mask;
        if (oneLeaf) {
            if (const LeafT* leaf = mAcc.probeConstLeaf(base)) {
                const openvdb::Index o = LeafT::coordToOffset(base);
                constexpr openvdb::Index dx = LeafT::DIM * LeafT::DIM, dy = LeafT::DIM, dz = 1;
                for (int i = 0; i < 8; ++i) {
                    const openvdb::Index off = o + ((i >> 2) & 1) * dx + ((i >> 1) & 1) * dy + (i & 1) * dz;
                    const bool on = leaf->isValueOn(off);
                    mActive[i] = on ? 1.0 : 0.0;
                    mValue[i] = on ? toVec(leaf->getValue(off)) : openvdb::Vec3d(0.0);
                }
                return;
            }
        }
        for (int i = 0; i < 8; ++i) {
            const openvdb::Coord c = base.offsetBy((i >> 2) & 1, (i >> 1) & 1, i & 1);
            ValueT val;
            const bool on = mAcc.probeValue(c, val);
            mActive[i] = on ? 1.0 : 0.0;
            mValue[i] = on ? toVec(val) : openvdb::Vec3d(0.0);
        }
    }

    static openvdb::Vec3d toVec(const ValueT& v) { return openvdb::Vec3d(double(v[0]), double(v[1]), double(v[2])); }

    openvdb::tree::ValueAccessor<const TreeT> mAcc;
    openvdb::Coord mBase;
    bool mValid = false;
    openvdb::Vec3d mValue[8];
    double mActive[8];
    std::size_t mLoads = 0;
};

} // namespace vdbhair
