/// @file FieldMoments.h
/// @brief The accumulation half of estimateTangentField() (TangentField.h): per-voxel moments of
/// the strands' segments, gathered chunk by chunk into paged storage, and the Eq. 9 direction,
/// coherence and spread read off them. Included by TangentField.cc only.
#pragma once

#include <vdbhair/SegmentWalk.h>
#include <vdbhair/field/Simd.h>
#include <vdbhair/strands/StrandSet.h>

#include <openvdb/openvdb.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <iterator>
#include <limits>
#include <memory>
#include <new>
#include <type_traits>
#include <unordered_map>
#include <vector>

namespace vdbhair {
namespace field_moments {

using openvdb::Coord;
using openvdb::Vec3d;

/// @brief First and second moments of the contributions to one voxel: s = Σ ℓ T and
/// M = Σ ℓ T Tᵀ, as three SIMD quadruples a = (s_x, s_y, s_z, M_xx), b = (M_yy, M_zz, M_xy,
/// M_xz), c = (M_yz, 0, 0, 0), so that adding a contribution is three multiply-adds.
/// trace(M) = Σ ℓ is the density.
struct Moments
{
    Float4 a = {0.f, 0.f, 0.f, 0.f}, b = {0.f, 0.f, 0.f, 0.f}, c = {0.f, 0.f, 0.f, 0.f};

    /// @brief The moments of a whole segment d (world, length len > 0): ℓ T = d and
    /// ℓ T Tᵀ = d dᵀ / len. A piece of it, fraction f of its length, contributes f times these.
    static Moments ofSegment(const Float4& d, float len)
    {
        const Float4 e = d * (1.f / len);
        Moments m;
        m.a = Float4{d[0], d[1], d[2], d[0] * e[0]};
        m.b = Float4{d[1] * e[1], d[2] * e[2], d[0] * e[1], d[0] * e[2]};
        m.c = Float4{d[1] * e[2], 0.f, 0.f, 0.f};
        return m;
    }
    void add(const Moments& o)
    {
        a += o.a;
        b += o.b;
        c += o.c;
    }
    void addScaled(const Moments& o, float f)
    {
        a += o.a * f;
        b += o.b * f;
        c += o.c * f;
    }
    float xx() const { return a[3]; }
    float yy() const { return b[0]; }
    float zz() const { return b[1]; }
    float xy() const { return b[2]; }
    float xz() const { return b[3]; }
    float yz() const { return c[0]; }
    float density() const { return xx() + yy() + zz(); }
    bool empty() const { return xx() == 0.f && yy() == 0.f && zz() == 0.f; }
};

/// Eq. 9 from the moments: v_t = normalize(s + M v_{t-1}), v_0 = 0.
inline openvdb::Vec3f robustDirection(const Moments& mo, int iterations)
{
    const Vec3d s(mo.a[0], mo.a[1], mo.a[2]);
    Vec3d v(0.0);
    for (int t = 0; t < iterations; ++t) {
        const Vec3d w = s + Vec3d(mo.xx() * v.x() + mo.xy() * v.y() + mo.xz() * v.z(),
                                  mo.xy() * v.x() + mo.yy() * v.y() + mo.yz() * v.z(),
                                  mo.xz() * v.x() + mo.yz() * v.y() + mo.zz() * v.z());
        const double len = w.length();
        if (!(len > 1e-30)) return openvdb::Vec3f(0.f);
        v = w / len;
    }
    return openvdb::Vec3f(float(v.x()), float(v.y()), float(v.z()));
}

/// |s| / Σ ℓ: 1 for parallel contributions, 0 where they cancel.
inline float coherenceOf(const Moments& mo)
{
    const double d = mo.density();
    if (!(d > 0.0)) return 0.f;
    const double s = std::sqrt(double(mo.a[0]) * mo.a[0] + double(mo.a[1]) * mo.a[1] + double(mo.a[2]) * mo.a[2]);
    return float(std::min(1.0, s / d));
}

/// 1 − vᵀ M v / Σ ℓ: the contributions' mean squared sine of their angle to v (1 if v is zero).
inline float spreadOf(const Moments& mo, const openvdb::Vec3f& v)
{
    const double d = mo.density();
    if (!(d > 0.0) || v.lengthSqr() == 0.f) return 1.f;
    const double x = v.x(), y = v.y(), z = v.z();
    const double vmv = mo.xx() * x * x + mo.yy() * y * y + mo.zz() * z * z +
                       2.0 * (mo.xy() * x * y + mo.xz() * x * z + mo.yz() * y * z);
    return float(std::min(1.0, std::max(0.0, 1.0 - vmv / d)));
}

/// @brief An array that grows by whole pages and never moves what it holds: a chunk's moments and
/// blocks. A std::vector that doubles copied its contents into fresh memory at every growth,
/// which the kernel had to clear first (clearing pages was a fifth of `field`'s CPU, these copies
/// part of it); here each element is written once, into the page it stays in. For trivially
/// copyable T.
template<typename T, unsigned kPageBits>
class PagedArray
{
    static_assert(std::is_trivially_copyable_v<T> && std::is_trivially_destructible_v<T>);
    static constexpr std::size_t kPage = std::size_t(1) << kPageBits;

    struct Free
    {
        void operator()(T* p) const { ::operator delete(p, std::align_val_t(alignof(T))); }
    };

public:
    std::size_t size() const { return mSize; }
    T& operator[](std::size_t i) { return mPages[i >> kPageBits].get()[i & (kPage - 1)]; }
    const T& operator[](std::size_t i) const { return mPages[i >> kPageBits].get()[i & (kPage - 1)]; }

    /// The new last element, uninitialized.
    T& grow()
    {
        if ((mSize & (kPage - 1)) == 0) {
            mPages.emplace_back(static_cast<T*>(::operator new(sizeof(T) * kPage, std::align_val_t(alignof(T)))));
        }
        return (*this)[mSize++];
    }

private:
    std::vector<std::unique_ptr<T, Free>> mPages;
    std::size_t mSize = 0;
};

/// The accumulation of one chunk of strands. Moments live in one array; each touched leaf-sized
/// block (8³ voxels) maps its voxels to slots in it. Consecutive flushes of a strand mostly hit
/// the same block, which is cached, so a flush costs a compare, an index and three SIMD adds.
struct Chunk
{
    static constexpr std::uint32_t kEmpty = 0xffffffffu;
    struct Block
    {
        std::uint32_t slot[512];
    };
    std::unordered_map<Coord, std::uint32_t> blockOf;  // block origin -> block index
    PagedArray<Block, 9> blocks;                       // 1 MiB pages
    std::vector<Coord> origins;
    PagedArray<Moments, 15> moments;                   // 1.5 MiB pages

    /// The block of @a origin, or nullptr.
    const Block* find(const Coord& origin) const
    {
        const auto it = blockOf.find(origin);
        return it == blockOf.end() ? nullptr : &blocks[it->second];
    }
};

/// Adds moments to a chunk, caching the block of the last voxel.
class ChunkWriter
{
public:
    explicit ChunkWriter(Chunk& c) : mChunk(c) {}

    /// Add @a m to voxel @a ijk (inlined: called for every voxel a strand enters).
    void add(const Coord& ijk, const Moments& m)
    {
        const Coord origin(ijk.x() & ~7, ijk.y() & ~7, ijk.z() & ~7);
        if (mSlots == nullptr || !sameCoord(origin, mOrigin)) selectBlock(origin);
        std::uint32_t& slot = mSlots[((ijk.x() & 7) << 6) | ((ijk.y() & 7) << 3) | (ijk.z() & 7)];
        if (slot == Chunk::kEmpty) {
            newSlot(slot, m);
        } else {
            mChunk.moments[slot].add(m);
        }
    }

    /// Whether a == b, without the branches of Coord::operator== (voxels change unpredictably).
    static bool sameCoord(const Coord& a, const Coord& b)
    {
        return ((a.x() ^ b.x()) | (a.y() ^ b.y()) | (a.z() ^ b.z())) == 0;
    }

private:
    __attribute__((noinline)) void selectBlock(const Coord& origin)
    {
        mOrigin = origin;
        const auto [it, inserted] = mChunk.blockOf.try_emplace(origin, std::uint32_t(mChunk.blocks.size()));
        if (inserted) {
            Chunk::Block& block = mChunk.blocks.grow();
            std::fill(std::begin(block.slot), std::end(block.slot), Chunk::kEmpty);
            mChunk.origins.push_back(origin);
        }
        mSlots = mChunk.blocks[it->second].slot;
    }

    __attribute__((noinline)) void newSlot(std::uint32_t& slot, const Moments& m)
    {
        slot = std::uint32_t(mChunk.moments.size());
        mChunk.moments.grow() = m;
    }

    Chunk& mChunk;
    Coord mOrigin;
    /// The cached block's slots (blocks never move); a chunk has one writer.
    std::uint32_t* mSlots = nullptr;
};

/// @brief Walks one chunk's strands through the voxels and adds their moments to the chunk.
///
/// Consecutive pieces in the same voxel (strands often take several segments per voxel) are summed
/// in registers and written to the chunk when the walk moves on. Per segment: the world segment
/// gives the moments of the whole segment once (Moments::ofSegment); the index-space segment
/// gives the voxels and the fraction of its length in each, by walkSegment() (SegmentWalk.h: a 3D
/// DDA that takes exactly |Δ| steps per axis and ends in the end vertex's voxel).
template<typename ToIndex>
class SegmentAccumulator
{
public:
    SegmentAccumulator(Chunk& chunk, const ToIndex& toIndex) : mWriter(chunk), mToIndex(toIndex) {}

    /// Add the n vertices at @a v (one strand, root first).
    void addStrand(const Vec3f* v, std::size_t n)
    {
        Vec3d ia = mToIndex(v[0]);
        Coord va = voxelOf(ia);
        Float4 pa = loadFloat3(v[0].asPointer());
        for (std::size_t j = 1; j < n; ++j) {
            const Vec3d ib = mToIndex(v[j]);
            const Coord vb = voxelOf(ib);
            const Float4 pb = loadFloat3(v[j].asPointer());
            const Float4 d = pb - pa;
            const float len2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
            if (len2 > 0.f) {
                const Moments u = Moments::ofSegment(d, std::sqrt(len2));
                if (ChunkWriter::sameCoord(va, vb)) {
                    add(va, u);  // the common case: the whole segment in one voxel
                } else {
                    walk(ia, ib, va, vb, u);
                }
            }
            ia = ib;
            va = vb;
            pa = pb;
        }
    }

    /// Write the pending moments out (at the end of the chunk).
    void flush()
    {
        if (!mPending.empty()) mWriter.add(mCurrent, mPending);
        mPending = Moments();
    }

private:
    void add(const Coord& ijk, const Moments& u)
    {
        if (!ChunkWriter::sameCoord(ijk, mCurrent)) {
            flush();
            mCurrent = ijk;
        }
        mPending.add(u);
    }

    void add(const Coord& ijk, const Moments& u, float f)
    {
        if (!ChunkWriter::sameCoord(ijk, mCurrent)) {
            flush();
            mCurrent = ijk;
        }
        mPending.addScaled(u, f);
    }

    /// The segment from @a a (voxel @a va) to @a b (voxel @a vb != va), index space, through
    /// every voxel it passes (SegmentWalk.h).
    void walk(const Vec3d& a, const Vec3d& b, const Coord& va, const Coord& vb, const Moments& u)
    {
        walkSegment(a, b, va, vb, [&](const Coord& c, double t0, double t1) { add(c, u, float(t1 - t0)); });
    }

    ChunkWriter mWriter;
    const ToIndex& mToIndex;
    Coord mCurrent{std::numeric_limits<int>::max()};
    Moments mPending;
};

} // namespace field_moments
} // namespace vdbhair
