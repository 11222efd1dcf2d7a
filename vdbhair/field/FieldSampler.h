/// @file FieldSampler.h
/// @brief Fast trilinear sampling of a vector grid at voxel centres, for streamlines.
///
/// BrickedField copies every leaf of the grid, with a one-voxel apron from its +x, +y, +z
/// neighbours, into a 9³ brick, so that the eight corners of any sampling cell whose lower corner
/// lies in a leaf are read from one brick without touching the tree. FieldSampler caches the
/// current brick and cell: streamlines take several steps per cell and many cells per brick, so a
/// step costs a few dozen arithmetic operations. Cells whose lower corner lies outside every leaf
/// (at the lower faces of the active region, or in tiles) fall back to the tree's accessor.
///
/// Inactive corners contribute nothing; sample() also returns the summed weight of the active
/// corners, so that callers can tell "outside the field" (no active corner) from "the field
/// vanishes here" (active corners whose vectors cancel).
#pragma once

#include <vdbhair/field/SegmentWalk.h>

#include <openvdb/math/Coord.h>
#include <openvdb/math/Vec3.h>
#include <openvdb/tree/LeafManager.h>
#include <openvdb/tree/ValueAccessor.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <unordered_map>
#include <vector>

namespace vdbhair {

/// Four floats: a vector (x, y, z) and an activity weight (w), blended as one SIMD value
/// (GCC/Clang vector extensions; compiled to scalar code where the target has no SIMD).
typedef float Float4 __attribute__((vector_size(16)));

/// @brief The leaves of a vector tree as 9³ bricks (see the file comment). Read-only after
/// construction, and safe to share between threads.
template<typename TreeT>
class BrickedField
{
public:
    using ValueT = typename TreeT::ValueType;
    using LeafT = typename TreeT::LeafNodeType;
    static_assert(LeafT::DIM == 8, "bricks assume 8³ leaves");
    static constexpr int N = 9;

    struct Brick
    {
        Float4 cell[N * N * N];  ///< x, y, z and w = 1 (active) or 0, indexed (x * N + y) * N + z
    };

    explicit BrickedField(const TreeT& tree) : mTree(tree)
    {
        openvdb::tree::LeafManager<const TreeT> leaves(tree);
        mBricks.reset(new Brick[leaves.leafCount()]);
        for (std::size_t i = 0; i < leaves.leafCount(); ++i) mIndex.emplace(key(leaves.leaf(i).origin()), std::uint32_t(i));
        leaves.foreach([&](const LeafT& leaf, std::size_t i) {
            openvdb::tree::ValueAccessor<const TreeT> acc(mTree);
            Brick& b = mBricks[i];
            const openvdb::Coord o = leaf.origin();
            // The leaf and its +x, +y, +z neighbours (nullptr where there is no leaf: tiles or background).
            const LeafT* nb[8];
            for (int n = 0; n < 8; ++n) nb[n] = n == 0 ? &leaf : acc.probeConstLeaf(o.offsetBy(8 * ((n >> 2) & 1), 8 * ((n >> 1) & 1), 8 * (n & 1)));
            for (int x = 0; x < N; ++x) {
                for (int y = 0; y < N; ++y) {
                    for (int z = 0; z < N; ++z) {
                        const int n = ((x >> 3) << 2) | ((y >> 3) << 1) | (z >> 3);
                        const openvdb::Index off = LeafT::coordToOffset(openvdb::Coord(x & 7, y & 7, z & 7));
                        ValueT v;
                        bool on;
                        if (nb[n]) {
                            on = nb[n]->isValueOn(off);
                            v = nb[n]->getValue(off);
                        } else {
                            on = acc.probeValue(o.offsetBy(x, y, z), v);
                        }
                        const int k = (x * N + y) * N + z;
                        b.cell[k] = on ? Float4{float(v[0]), float(v[1]), float(v[2]), 1.f} : Float4{0.f, 0.f, 0.f, 0.f};
                    }
                }
            }
        });
    }

    /// The brick of the leaf with origin @a origin (multiples of 8), or nullptr.
    const Brick* find(const openvdb::Coord& origin) const
    {
        const auto it = mIndex.find(key(origin));
        return it == mIndex.end() ? nullptr : &mBricks[it->second];
    }

    const TreeT& tree() const { return mTree; }

    /// @brief The lower corner's cell of the sampling cell whose lower corner is (bx, by, bz), or
    /// nullptr where no leaf holds that corner; @a origin / @a brick cache the last brick.
    const Float4* cell(int bx, int by, int bz, openvdb::Coord& origin, const Brick*& brick) const
    {
        const openvdb::Coord o(bx & ~7, by & ~7, bz & ~7);
        if (o != origin) {
            origin = o;
            brick = find(o);
        }
        return brick ? brick->cell + ((bx & 7) * N + (by & 7)) * N + (bz & 7) : nullptr;
    }

    /// @brief Trilinear blend of the cell at @a c with fractions (fx, fy, fz) (see FieldSampler).
    static Float4 blend(const Float4* c, float fx, float fy, float fz)
    {
        const Float4 z00 = c[0] + (c[1] - c[0]) * fz;
        const Float4 z01 = c[N] + (c[N + 1] - c[N]) * fz;
        const Float4 z10 = c[N * N] + (c[N * N + 1] - c[N * N]) * fz;
        const Float4 z11 = c[N * N + N] + (c[N * N + N + 1] - c[N * N + N]) * fz;
        const Float4 y0 = z00 + (z01 - z00) * fy;
        const Float4 y1 = z10 + (z11 - z10) * fy;
        return y0 + (y1 - y0) * fx;
    }

private:
    static std::uint64_t key(const openvdb::Coord& o)
    {
        return (std::uint64_t(std::uint32_t(o.x()) >> 3) << 42) ^ (std::uint64_t(std::uint32_t(o.y()) >> 3) << 21) ^
               std::uint64_t(std::uint32_t(o.z()) >> 3);
    }

    const TreeT& mTree;
    std::unique_ptr<Brick[]> mBricks;
    std::unordered_map<std::uint64_t, std::uint32_t> mIndex;
};

/// @brief Trilinear sampling over a BrickedField, with the current brick and cell cached.
/// @warning Not thread-safe: one sampler per thread (it owns a ValueAccessor).
template<typename TreeT>
class FieldSampler
{
public:
    using ValueT = typename TreeT::ValueType;
    using Bricks = BrickedField<TreeT>;
    static constexpr int N = Bricks::N;

    explicit FieldSampler(const Bricks& bricks) : mBricks(bricks), mAcc(bricks.tree()) {}

    /// @brief Sample at index-space position @a p: the trilinear blend of the corners' vectors in
    /// x, y, z, and in w the summed weight of the active corners (0: outside the field).
    /// Inactive corners hold zero vectors, so they contribute nothing to x, y, z.
    Float4 sample(const openvdb::Vec3d& p)
    {
        const int bx = floorToInt(p.x()), by = floorToInt(p.y()), bz = floorToInt(p.z());
        if (!mValid || bx != mBase[0] || by != mBase[1] || bz != mBase[2]) load(bx, by, bz);
        // Corners at +0, +1 (z), +N (y), +N*N (x): three nested lerps, four lanes at a time.
        return Bricks::blend(mCell, float(p.x() - bx), float(p.y() - by), float(p.z() - bz));
    }

    /// @brief As above, as a vector and a weight.
    double sample(const openvdb::Vec3d& p, openvdb::Vec3d& value)
    {
        const Float4 r = sample(p);
        value = openvdb::Vec3d(r[0], r[1], r[2]);
        return r[3];
    }

private:
    void load(int bx, int by, int bz)
    {
        mBase[0] = bx; mBase[1] = by; mBase[2] = bz;
        mValid = true;
        const openvdb::Coord origin(bx & ~7, by & ~7, bz & ~7);
        if (!mHaveBrick || origin != mOrigin) {
            mOrigin = origin;
            mHaveBrick = true;
            mBrick = mBricks.find(origin);
        }
        if (mBrick) {
            mCell = mBrick->cell + ((bx & 7) * N + (by & 7)) * N + (bz & 7);
            return;
        }
        // No leaf holds the lower corner: read the corners through the tree into a small
        // brick-shaped scratch (only the eight corner slots are used).
        for (int i = 0; i < 8; ++i) {
            const int dx = i >> 2, dy = (i >> 1) & 1, dz = i & 1;
            ValueT val;
            const bool on = mAcc.probeValue(openvdb::Coord(bx + dx, by + dy, bz + dz), val);
            mScratch[(dx * N + dy) * N + dz] = on ? Float4{float(val[0]), float(val[1]), float(val[2]), 1.f} : Float4{0.f, 0.f, 0.f, 0.f};
        }
        mCell = mScratch;
    }

    const Bricks& mBricks;
    openvdb::tree::ValueAccessor<const TreeT> mAcc;
    int mBase[3] = {0, 0, 0};
    bool mValid = false;
    openvdb::Coord mOrigin;
    bool mHaveBrick = false;
    const typename Bricks::Brick* mBrick = nullptr;
    const Float4* mCell = nullptr;
    Float4 mScratch[N * N + N + 2] = {};
};

} // namespace vdbhair
