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
///
/// Bricks are found by leaf coordinates in a dense table over the leaves' bounding box (a hash
/// map only for scattered leaves), and where no leaf is BrickedField::brickAt() returns an
/// all-zero brick rather than nullptr: the streamline tracer's SIMD kernel then blends first and
/// tests the weight afterwards, with no branch per lane (impl/LaneTracer.h).
///
/// FieldDirectionSampler is the streamline engine's sampler for a vector grid (Streamline.h).
#pragma once

#include <vdbhair/Memory.h>
#include <vdbhair/SegmentWalk.h>
#include <vdbhair/field/FieldMapping.h>
#include <vdbhair/field/Simd.h>
#include <vdbhair/field/Streamline.h>

#include <openvdb/openvdb.h>
#include <openvdb/math/Coord.h>
#include <openvdb/math/Vec3.h>
#include <openvdb/tree/LeafManager.h>
#include <openvdb/tree/ValueAccessor.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <thread>
#include <unordered_map>
#include <vector>

namespace vdbhair {

/// @brief The leaves of a vector tree as 9³ bricks (see the file comment), filled on first use.
/// Safe to share between threads (a brick is filled once, by the first thread that asks).
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
        /// x, y, z and w = 1 (active) or 0, indexed (x * N + y) * N + z: a vector and an activity
        /// weight, blended as one SIMD value
        Float4 cell[N * N * N];
    };

    /// @brief Index the leaves of @a tree. Bricks are filled on first use (brickAt()), by
    /// whichever thread asks first: a retrace starts tracing at once instead of first mapping
    /// and filling every brick (about 10 MB for 100,000 strands, mostly page faults that do not
    /// get faster with more threads), and bricks no streamline enters cost nothing.
    /// @param scalar optional: a float tree sampled through the same cells (FieldSampler::
    /// sampleScalar()), stored beside each brick as 9³ floats, its values at @a tree's active
    /// voxels and 0 elsewhere: a quarter of the bytes of a vector brick holding it.
    explicit BrickedField(const TreeT& tree, const openvdb::FloatTree* scalar = nullptr) : mTree(tree), mScalarTree(scalar)
    {
        openvdb::tree::LeafManager<const TreeT> leaves(tree);
        const std::size_t count = leaves.leafCount();
        // One more brick than leaves: the last stays all zero (see brickAt()).
        mBricks.reset(new Brick[count + 1]);
        adviseHugePages(mBricks.get(), (count + 1) * sizeof(Brick));  // 11.7 KB a leaf, faulted in on first use (Memory.h)
        mState.reset(new std::atomic<std::uint8_t>[count + 1]);
        mLeaves.resize(count);
        for (std::size_t i = 0; i < count; ++i) {
            mLeaves[i] = &leaves.leaf(i);
            mState[i].store(kEmpty, std::memory_order_relaxed);
        }
        mZero = &mBricks[count];
        std::fill(std::begin(mBricks[count].cell), std::end(mBricks[count].cell), Float4{0.f, 0.f, 0.f, 0.f});
        if (scalar) {
            mScalar.reset(new float[(count + 1) * kCells]);
            adviseHugePages(mScalar.get(), (count + 1) * kCells * sizeof(float));
            std::fill(mScalar.get() + count * kCells, mScalar.get() + (count + 1) * kCells, 0.f);
        }
        mState[count].store(kReady, std::memory_order_release);
        buildIndex(leaves);
    }

    /// The brick of the leaf with origin @a origin (multiples of 8), or nullptr.
    const Brick* find(const openvdb::Coord& origin) const
    {
        const Brick* b = brickAt(origin.x() >> 3, origin.y() >> 3, origin.z() >> 3);
        return b == mZero ? nullptr : b;
    }

    /// @brief The brick of the leaf at leaf coordinates (lx, ly, lz) (index coordinates >> 3), or
    /// the all-zero brick where there is no leaf. Never nullptr, so a sampler can blend first and
    /// test afterwards: a blend in the zero brick has weight 0, as outside the field.
    const Brick* brickAt(int lx, int ly, int lz) const
    {
        if (!mTable.empty()) {
            // Unsigned compares fold the lower and upper bounds into one test per axis.
            const std::uint32_t x = std::uint32_t(lx - mLo[0]), y = std::uint32_t(ly - mLo[1]), z = std::uint32_t(lz - mLo[2]);
            if (x >= mDim[0] || y >= mDim[1] || z >= mDim[2]) return mZero;
            return ready(mTable[(std::size_t(x) * mDim[1] + y) * mDim[2] + z]);
        }
        const auto it = mIndex.find(openvdb::Coord(lx, ly, lz));
        return it == mIndex.end() ? mZero : ready(it->second);
    }

    const TreeT& tree() const { return mTree; }
    /// The scalar tree of the constructor, or nullptr.
    const openvdb::FloatTree* scalarTree() const { return mScalarTree; }
    /// The scalar cells beside brick @a b (a brick of this field; a scalar tree is given).
    const float* scalarCells(const Brick* b) const { return mScalar.get() + std::size_t(b - mBricks.get()) * kCells; }
    /// The all-zero brick brickAt() returns where there is no leaf.
    const Brick* zeroBrick() const { return mZero; }

    /// @brief Trilinear blend of the cell at @a c with fractions (fx, fy, fz) (see FieldSampler):
    /// corners at +0, +1 (z), +N (y), +N*N (x). The two corners of a z pair are adjacent, so
    /// each pair is one eight-float value: lerp the pairs in x, then y (eight lanes at a time,
    /// one AVX operation each where the caller is compiled for it), then the pair's halves in z.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"  // Float8 values stay inside this inlined function (Simd.h)
    __attribute__((always_inline)) static Float4 blend(const Float4* c, float fx, float fy, float fz)
    {
        const Float8 c00 = loadPair(c), c01 = loadPair(c + N), c10 = loadPair(c + N * N), c11 = loadPair(c + N * N + N);
        // Scalar operands on purpose: a vector of copies built here would be lowered for SSE
        // (this function has the default target) before it is inlined into the AVX2 clone, while
        // a scalar operand becomes one broadcast there.
        const Float8 y0 = c00 + (c10 - c00) * fx;  // corners (y0, z0|z1), lerped in x
        const Float8 y1 = c01 + (c11 - c01) * fx;
        const Float8 z = y0 + (y1 - y0) * fy;      // (z0 | z1)
        const Float4 z0 = lowHalf(z), z1 = highHalf(z);
        return z0 + (z1 - z0) * fz;
    }
#pragma GCC diagnostic pop

    /// @brief blend() in four-float operations: the same operations on every lane in the same
    /// order, so the same values bit for bit, for callers compiled for the x86-64 baseline
    /// (FieldSampler, and through it the consistent retrace). There GCC builds blend()'s Float8
    /// of copies of @a fx as eight scalar stores to the stack and two 16-byte loads of them,
    /// which the processor cannot forward from the stores: measured, those two loads were 37 %
    /// of FieldSampler::sample()'s time. A Float4 times a float is one shuffle in a register.
    __attribute__((always_inline)) static Float4 blend4(const Float4* c, float fx, float fy, float fz)
    {
        const Float4 y0z0 = c[0] + (c[N * N] - c[0]) * fx;  // blend()'s y0, its z0 and z1 halves
        const Float4 y0z1 = c[1] + (c[N * N + 1] - c[1]) * fx;
        const Float4 y1z0 = c[N] + (c[N * N + N] - c[N]) * fx;  // y1
        const Float4 y1z1 = c[N + 1] + (c[N * N + N + 1] - c[N + 1]) * fx;
        const Float4 z0 = y0z0 + (y1z0 - y0z0) * fy;
        const Float4 z1 = y0z1 + (y1z1 - y0z1) * fy;
        return z0 + (z1 - z0) * fz;
    }

    /// @brief blend4() of one float per cell: the same operations in the same order, so a scalar
    /// gives bit for bit the lane a vector brick holding it in that lane would give.
    static float blend1(const float* c, float fx, float fy, float fz)
    {
        const float y0z0 = c[0] + (c[N * N] - c[0]) * fx;
        const float y0z1 = c[1] + (c[N * N + 1] - c[1]) * fx;
        const float y1z0 = c[N] + (c[N * N + N] - c[N]) * fx;
        const float y1z1 = c[N + 1] + (c[N * N + N + 1] - c[N + 1]) * fx;
        const float z0 = y0z0 + (y1z0 - y0z0) * fy;
        const float z1 = y0z1 + (y1z1 - y0z1) * fy;
        return z0 + (z1 - z0) * fz;
    }

private:
    enum : std::uint8_t { kEmpty, kFilling, kReady };
    static constexpr std::size_t kCells = std::size_t(N) * N * N;

    /// @brief Brick @a i, filled first if nobody has yet (the first caller fills it, others
    /// wait for it: a brick is filled once, whoever asks).
    const Brick* ready(std::uint32_t i) const
    {
        if (__builtin_expect(mState[i].load(std::memory_order_acquire) != kReady, 0)) {
            std::uint8_t expected = kEmpty;
            if (mState[i].compare_exchange_strong(expected, kFilling, std::memory_order_acq_rel)) {
                fill(i);
                mState[i].store(kReady, std::memory_order_release);
            } else {
                while (mState[i].load(std::memory_order_acquire) != kReady) std::this_thread::yield();
            }
        }
        return &mBricks[i];
    }

    /// @brief Copy leaf @a i and its one-voxel apron from the +x, +y, +z neighbours into brick i.
    void fill(std::uint32_t i) const
    {
        openvdb::tree::ValueAccessor<const TreeT> acc(mTree);
        const LeafT& leaf = *mLeaves[i];
        Brick& b = mBricks[i];
        float* scalar = mScalar ? mScalar.get() + std::size_t(i) * kCells : nullptr;
        std::unique_ptr<openvdb::tree::ValueAccessor<const openvdb::FloatTree>> scalarAcc;
        if (scalar) scalarAcc.reset(new openvdb::tree::ValueAccessor<const openvdb::FloatTree>(*mScalarTree));
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
                    if (scalar) scalar[k] = on ? scalarAcc->getValue(o.offsetBy(x, y, z)) : 0.f;
                }
            }
        }
    }

    /// @brief Leaf coordinates to brick indices. A dense table over the leaves' bounding box
    /// (one load, no hashing) when it costs at most 64 entries per leaf, i.e. under 3% of the
    /// bricks' own memory; a hash map for scattered leaves.
    void buildIndex(const openvdb::tree::LeafManager<const TreeT>& leaves)
    {
        const std::size_t count = leaves.leafCount();
        if (count == 0) return;
        int lo[3], hi[3];
        for (int k = 0; k < 3; ++k) { lo[k] = std::numeric_limits<int>::max(); hi[k] = std::numeric_limits<int>::min(); }
        for (std::size_t i = 0; i < count; ++i) {
            const openvdb::Coord o = leaves.leaf(i).origin();
            for (int k = 0; k < 3; ++k) { lo[k] = std::min(lo[k], o[k] >> 3); hi[k] = std::max(hi[k], o[k] >> 3); }
        }
        double cells = 1.0;
        for (int k = 0; k < 3; ++k) cells *= double(hi[k]) - double(lo[k]) + 1.0;
        if (cells <= 64.0 * double(count) + 4096.0) {
            for (int k = 0; k < 3; ++k) { mLo[k] = lo[k]; mDim[k] = std::uint32_t(hi[k] - lo[k] + 1); }
            mTable.assign(std::size_t(cells), std::uint32_t(count));  // count: the zero brick
            for (std::size_t i = 0; i < count; ++i) {
                const openvdb::Coord o = leaves.leaf(i).origin();
                const std::size_t x = std::size_t((o.x() >> 3) - lo[0]), y = std::size_t((o.y() >> 3) - lo[1]), z = std::size_t((o.z() >> 3) - lo[2]);
                mTable[(x * mDim[1] + y) * mDim[2] + z] = std::uint32_t(i);
            }
        } else {
            mIndex.reserve(count);
            for (std::size_t i = 0; i < count; ++i) {
                const openvdb::Coord o = leaves.leaf(i).origin();
                mIndex.emplace(openvdb::Coord(o.x() >> 3, o.y() >> 3, o.z() >> 3), std::uint32_t(i));
            }
        }
    }

    const TreeT& mTree;
    const openvdb::FloatTree* mScalarTree;
    std::unique_ptr<Brick[]> mBricks;                       ///< filled on first use (mState)
    std::unique_ptr<float[]> mScalar;                       ///< kCells per brick, filled with it
    std::unique_ptr<std::atomic<std::uint8_t>[]> mState;    ///< per brick: kEmpty, kFilling, kReady
    std::vector<const LeafT*> mLeaves;
    const Brick* mZero = nullptr;
    std::vector<std::uint32_t> mTable;  ///< dense index (empty: use mIndex)
    int mLo[3] = {0, 0, 0};
    std::uint32_t mDim[3] = {0, 0, 0};
    std::unordered_map<openvdb::Coord, std::uint32_t> mIndex;  ///< leaf coordinates -> brick
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

    explicit FieldSampler(const Bricks& bricks) : mBricks(bricks), mAcc(bricks.tree())
    {
        if (bricks.scalarTree()) mScalarAcc.reset(new openvdb::tree::ValueAccessor<const openvdb::FloatTree>(*bricks.scalarTree()));
    }

    /// @brief Sample at index-space position @a p: the trilinear blend of the corners' vectors in
    /// x, y, z, and in w the summed weight of the active corners (0: outside the field).
    /// Inactive corners hold zero vectors, so they contribute nothing to x, y, z.
    Float4 sample(const openvdb::Vec3d& p)
    {
        const int bx = floorIndex(p.x()), by = floorIndex(p.y()), bz = floorIndex(p.z());
        if (!mValid || bx != mBase[0] || by != mBase[1] || bz != mBase[2]) load(bx, by, bz);
        // Corners at +0, +1 (z), +N (y), +N*N (x): three nested lerps, four lanes at a time.
        return Bricks::blend4(mCell, float(p.x() - bx), float(p.y() - by), float(p.z() - bz));
    }

    /// @brief The bricks' scalar (BrickedField's @a scalar) at index-space position @a p, blended
    /// with sample()'s corners and weights: bit for bit the lane a vector brick holding it there
    /// would give (the active corners' values, weighted; inactive corners count 0).
    float sampleScalar(const openvdb::Vec3d& p)
    {
        const int bx = floorIndex(p.x()), by = floorIndex(p.y()), bz = floorIndex(p.z());
        if (!mValid || bx != mBase[0] || by != mBase[1] || bz != mBase[2]) load(bx, by, bz);
        return Bricks::blend1(mScalarCell, float(p.x() - bx), float(p.y() - by), float(p.z() - bz));
    }

    /// @brief sample() at each of @a n scattered index-space points @a p (the vertices of a
    /// strand, about a voxel apart), into @a out. Each point's cell is found and its corners'
    /// cache lines requested first, then all are blended: with a field larger than the cache,
    /// the loads of many points overlap instead of waiting one after another. Same values as
    /// sample() at each point.
    void sampleScattered(const openvdb::Vec3d* p, std::size_t n, Float4* out)
    {
        mCells.resize(n);
        for (std::size_t i = 0; i < n; ++i) {
            const int bx = floorIndex(p[i].x()), by = floorIndex(p[i].y()), bz = floorIndex(p[i].z());
            const typename Bricks::Brick* brick = mBricks.brickAt(bx >> 3, by >> 3, bz >> 3);
            if (brick == mBricks.zeroBrick()) {
                mCells[i] = nullptr;  // no leaf holds the lower corner: through the tree below
                continue;
            }
            const Float4* c = brick->cell + ((bx & 7) * N + (by & 7)) * N + (bz & 7);
            __builtin_prefetch(c);
            __builtin_prefetch(c + N);
            __builtin_prefetch(c + N * N);
            __builtin_prefetch(c + N * N + N);
            mCells[i] = c;
        }
        for (std::size_t i = 0; i < n; ++i) {
            if (!mCells[i]) {
                out[i] = sample(p[i]);
                continue;
            }
            const openvdb::Vec3d& q = p[i];
            out[i] = Bricks::blend4(mCells[i], float(q.x() - floorIndex(q.x())), float(q.y() - floorIndex(q.y())), float(q.z() - floorIndex(q.z())));
        }
    }

    /// @brief As above, as a vector and a weight.
    double sample(const openvdb::Vec3d& p, openvdb::Vec3d& value)
    {
        const Float4 r = sample(p);
        value = openvdb::Vec3d(r[0], r[1], r[2]);
        return r[3];
    }

private:
    /// floor(x), for any x: positions far outside the grid (or NaN) clamp to ±2^30, where no
    /// leaf is, instead of overflowing the int.
    static int floorIndex(double x)
    {
        constexpr double kLimit = double(1 << 30);
        return floorToInt(std::min(kLimit, std::max(-kLimit, x)));  // this order maps NaN to -kLimit
    }

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
            const int offset = ((bx & 7) * N + (by & 7)) * N + (bz & 7);
            mCell = mBrick->cell + offset;
            if (mScalarAcc) mScalarCell = mBricks.scalarCells(mBrick) + offset;
            return;
        }
        // No leaf holds the lower corner: read the corners through the tree into a small
        // brick-shaped scratch (only the eight corner slots are used).
        for (int i = 0; i < 8; ++i) {
            const int dx = i >> 2, dy = (i >> 1) & 1, dz = i & 1;
            ValueT val;
            const openvdb::Coord ijk(bx + dx, by + dy, bz + dz);
            const bool on = mAcc.probeValue(ijk, val);
            mScratch[(dx * N + dy) * N + dz] = on ? Float4{float(val[0]), float(val[1]), float(val[2]), 1.f} : Float4{0.f, 0.f, 0.f, 0.f};
            if (mScalarAcc) mScalarScratch[(dx * N + dy) * N + dz] = on ? mScalarAcc->getValue(ijk) : 0.f;
        }
        mCell = mScratch;
        mScalarCell = mScalarScratch;
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
    std::unique_ptr<openvdb::tree::ValueAccessor<const openvdb::FloatTree>> mScalarAcc;  ///< with a scalar tree
    const float* mScalarCell = nullptr;
    float mScalarScratch[N * N + N + 2] = {};
    std::vector<const Float4*> mCells;  ///< sampleScattered()'s cells (nullptr: through the tree)
};

/// @brief The streamline engine's sampler for a vector grid (the sampler concept of
/// Streamline.h): the unit direction of the trilinear blend (FieldSampler) at a world point,
/// Left where no corner of the cell is active, Vanished where the blend is no longer than
/// @a vanishThreshold times the active corners' weight (opposing directions cancel, or zero
/// vectors). The test and the normalization are in float, as the lane kernel's.
/// @warning Not thread-safe: one per thread.
template<typename TreeT>
class FieldDirectionSampler
{
public:
    FieldDirectionSampler(const BrickedField<TreeT>& bricks, const FieldMapping& map, double vanishThreshold)
        : mSampler(bricks), mMap(map), mThreshold(float(vanishThreshold)) {}

    SampleStatus direction(const openvdb::Vec3d& worldPos, openvdb::Vec3d& unitDir)
    {
        const Float4 r = mSampler.sample(mMap.worldToIndex(worldPos));
        if (!(r[3] > 0.f)) return SampleStatus::Left;
        const float len2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
        const float limit = mThreshold * r[3];
        if (!(len2 > limit * limit)) return SampleStatus::Vanished;
        const float inv = 1.f / std::sqrt(len2);
        unitDir = openvdb::Vec3d(r[0] * inv, r[1] * inv, r[2] * inv);
        return SampleStatus::Ok;
    }

private:
    FieldSampler<TreeT> mSampler;
    const FieldMapping& mMap;
    float mThreshold;
};

} // namespace vdbhair
