#include "TangentField.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/field/FieldMapping.h>
#include <vdbhair/field/SegmentWalk.h>
#include <vdbhair/strands/Measures.h>

#include <openvdb/tree/LeafManager.h>
#include <openvdb/tree/ValueAccessor.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <array>
#include <cmath>
#include <limits>
#include <unordered_map>

namespace vdbhair {

namespace {

using openvdb::Coord;
using openvdb::Vec3d;

/// First and second moments of the contributions to one voxel: s = Σ ℓ T, M = Σ ℓ T Tᵀ
/// (xx, yy, zz, xy, xz, yz). trace(M) = Σ ℓ is the density.
struct Moments
{
    float s[3] = {0.f, 0.f, 0.f};
    float m[6] = {0.f, 0.f, 0.f, 0.f, 0.f, 0.f};

    /// Add a piece of length @a l of a segment whose tangent T gives @a t = T and
    /// @a tt = (xx, yy, zz, xy, xz, yz) of T Tᵀ (computed once per segment).
    void add(const float* t, const float* tt, float l)
    {
        for (int k = 0; k < 3; ++k) s[k] += l * t[k];
        for (int k = 0; k < 6; ++k) m[k] += l * tt[k];
    }
    void add(const Moments& o)
    {
        for (int k = 0; k < 3; ++k) s[k] += o.s[k];
        for (int k = 0; k < 6; ++k) m[k] += o.m[k];
    }
    bool empty() const { return m[0] == 0.f && m[1] == 0.f && m[2] == 0.f; }
};

/// Eq. 9 from the moments: v_t = normalize(s + M v_{t-1}), v_0 = 0.
openvdb::Vec3f robustDirection(const Moments& mo, int iterations)
{
    const Vec3d s(mo.s[0], mo.s[1], mo.s[2]);
    Vec3d v(0.0);
    for (int t = 0; t < iterations; ++t) {
        const Vec3d w = s + Vec3d(mo.m[0] * v.x() + mo.m[3] * v.y() + mo.m[4] * v.z(),
                                  mo.m[3] * v.x() + mo.m[1] * v.y() + mo.m[5] * v.z(),
                                  mo.m[4] * v.x() + mo.m[5] * v.y() + mo.m[2] * v.z());
        const double len = w.length();
        if (!(len > 1e-30)) return openvdb::Vec3f(0.f);
        v = w / len;
    }
    return openvdb::Vec3f(float(v.x()), float(v.y()), float(v.z()));
}

/// The accumulation of one chunk of strands. Moments live in one array; each touched leaf-sized
/// block (8³ voxels) maps its voxels to slots in it. Consecutive flushes of a strand mostly hit
/// the same block, which is cached, so a flush costs a compare, an index and nine adds.
struct Chunk
{
    static constexpr std::uint32_t kEmpty = 0xffffffffu;
    struct Block
    {
        std::uint32_t slot[512];
    };
    std::unordered_map<std::uint64_t, std::uint32_t> blockOf;  // packed block coordinate -> block index
    std::vector<Block> blocks;
    std::vector<Coord> origins;
    std::vector<Moments> moments;

    static std::uint64_t key(const Coord& origin)
    {
        return (std::uint64_t(std::uint32_t(origin.x()) >> 3) << 42) ^ (std::uint64_t(std::uint32_t(origin.y()) >> 3) << 21) ^
               std::uint64_t(std::uint32_t(origin.z()) >> 3);
    }
    /// The block of @a origin, or nullptr.
    const Block* find(const Coord& origin) const
    {
        const auto it = blockOf.find(key(origin));
        return it == blockOf.end() ? nullptr : &blocks[it->second];
    }
};

/// Adds moments to a chunk, caching the block of the last voxel.
class ChunkWriter
{
public:
    explicit ChunkWriter(Chunk& c) : mChunk(c) {}

    void add(const Coord& ijk, const Moments& m)
    {
        const Coord origin(ijk.x() & ~7, ijk.y() & ~7, ijk.z() & ~7);
        if (mBlock == Chunk::kEmpty || origin != mOrigin) {
            mOrigin = origin;
            const auto [it, inserted] = mChunk.blockOf.try_emplace(Chunk::key(origin), std::uint32_t(mChunk.blocks.size()));
            if (inserted) {
                mChunk.blocks.emplace_back();
                std::fill(std::begin(mChunk.blocks.back().slot), std::end(mChunk.blocks.back().slot), Chunk::kEmpty);
                mChunk.origins.push_back(origin);
            }
            mBlock = it->second;
        }
        std::uint32_t& slot = mChunk.blocks[mBlock].slot[((ijk.x() & 7) << 6) | ((ijk.y() & 7) << 3) | (ijk.z() & 7)];
        if (slot == Chunk::kEmpty) {
            slot = std::uint32_t(mChunk.moments.size());
            mChunk.moments.push_back(m);
        } else {
            mChunk.moments[slot].add(m);
        }
    }

private:
    Chunk& mChunk;
    Coord mOrigin;
    std::uint32_t mBlock = Chunk::kEmpty;
};

/// Strands are split into this many chunks whatever the thread count (determinism).
std::size_t chunkCount(std::size_t strands) { return std::min<std::size_t>(16, std::max<std::size_t>(1, strands / 256)); }

void checkParams(const StrandSet& strands, const FieldParams& p, const char* where)
{
    if (strands.empty()) throw ValueError(std::string(where) + ": the hairstyle has no strands");
    if (!(p.voxelSize > 0.0) || !std::isfinite(p.voxelSize)) {
        throw ValueError(std::string(where) + ": voxel size " + std::to_string(p.voxelSize) + " must be a positive finite length");
    }
    // OpenVDB refuses transforms whose scale determinant is within 1e-15 of zero.
    const double lattice = p.space == FieldSpace::Scalp ? p.voxelSize / p.scalp.radius : p.voxelSize;
    if (lattice < 2e-5) {
        throw ValueError(std::string(where) + ": voxel size " + std::to_string(p.voxelSize) +
                         " is below OpenVDB's smallest voxel size (about 2e-5" +
                         (p.space == FieldSpace::Scalp ? " of the scalp radius" : " world units") +
                         "); use a larger voxel or scale the hairstyle up");
    }
    if (p.iterations < 1) throw ValueError(std::string(where) + ": iterations " + std::to_string(p.iterations) + " must be at least 1");
    if (p.space == FieldSpace::Scalp && !(p.scalp.radius > 0.0)) {
        throw ValueError(std::string(where) + ": scalp radius " + std::to_string(p.scalp.radius) + " must be positive");
    }
}

/// The grid transform and the world-to-index mapping of one level.
FieldMapping mappingFor(const FieldParams& p, double voxelSize)
{
    if (p.space == FieldSpace::Scalp) {
        // (u, v, w) voxel size: the world voxel size at the scalp, in units of the radius.
        return FieldMapping(openvdb::math::Transform::createLinearTransform(voxelSize / p.scalp.radius), p.scalp);
    }
    return FieldMapping(openvdb::math::Transform::createLinearTransform(voxelSize));
}

std::uint64_t visitBound(const StrandSet& strands, const FieldMapping& map)
{
    return tbb::parallel_reduce(
        tbb::blocked_range<std::size_t>(0, strands.numStrands(), 256), std::uint64_t(0),
        [&](const tbb::blocked_range<std::size_t>& r, std::uint64_t acc) {
            for (std::size_t i = r.begin(); i != r.end(); ++i) {
                Vec3d a = map.worldToIndex(Vec3d(strands.root(i)));
                for (std::size_t v = strands.begin(i) + 1; v < strands.end(i); ++v) {
                    const Vec3d b = map.worldToIndex(Vec3d(strands.positions[v]));
                    acc += segmentVoxelBound(a, b);
                    a = b;
                }
                if (acc > (std::uint64_t(1) << 62)) return acc;
            }
            return acc;
        },
        [](std::uint64_t a, std::uint64_t b) { return std::min(a + b, std::uint64_t(1) << 62); });
}

TangentField estimateLevel(const StrandSet& strands, const FieldParams& p, double voxelSize, int level, int levels,
                           bool threaded, openvdb::util::NullInterrupter* interrupter)
{
    const FieldMapping map = mappingFor(p, voxelSize);

    // Bounds before any allocation: index coordinates must fit OpenVDB's int32 Coord, and the
    // voxel visits the cap.
    const BBox box = computeBBox(strands);
    for (const Vec3f& corner : {box.min, box.max}) {
        const Vec3d ip = map.worldToIndex(Vec3d(corner));
        for (int k = 0; k < 3; ++k) {
            if (!(std::abs(ip[k]) < double(1 << 30))) {
                throw LimitError("estimateTangentField: voxel size " + std::to_string(voxelSize) +
                                 " puts the hairstyle at index " + std::to_string(ip[k]) +
                                 ", beyond the grid's index range of ±2^30");
            }
        }
    }
    const std::uint64_t bound = visitBound(strands, map);
    if (bound > p.maxVoxels) {
        throw LimitError("estimateTangentField: voxel size " + std::to_string(voxelSize) + " needs up to " +
                         std::to_string(bound) + " voxel visits, more than the cap of " +
                         std::to_string(p.maxVoxels) + " (raise --max-voxels or the voxel size)");
    }

    // Accumulate the moments, chunk by chunk (each chunk in strand order).
    const std::size_t nS = strands.numStrands(), nChunks = chunkCount(nS);
    // Chunks of spatially sorted strands: neighbouring strands share voxels, so a chunk's
    // moments stay small and in cache.
    const std::vector<std::uint32_t> order = spatialOrder(strands);
    std::vector<Chunk> chunks(nChunks);
    auto accumulateChunk = [&](std::size_t c) {
        ChunkWriter writer(chunks[c]);
        Coord current(std::numeric_limits<int>::max());
        Moments pending;
        auto flush = [&]() {
            if (pending.empty()) return;
            writer.add(current, pending);
            pending = Moments();
        };
        const std::size_t first = nS * c / nChunks, last = nS * (c + 1) / nChunks;
        for (std::size_t o = first; o < last; ++o) {
            if (interrupter && (o & 255) == 0 && interrupter->wasInterrupted()) return;
            const std::size_t i = order[o];
            Vec3d pa(strands.root(i));
            Vec3d ia = map.worldToIndex(pa);
            for (std::size_t v = strands.begin(i) + 1; v < strands.end(i); ++v) {
                const Vec3d pb(strands.positions[v]);
                const Vec3d ib = map.worldToIndex(pb);
                const Vec3d seg = pb - pa;
                const double len = seg.length();
                if (len > 0.0) {
                    const float t[3] = {float(seg.x() / len), float(seg.y() / len), float(seg.z() / len)};
                    const float tt[6] = {t[0] * t[0], t[1] * t[1], t[2] * t[2], t[0] * t[1], t[0] * t[2], t[1] * t[2]};
                    walkSegment(ia, ib, [&](const Coord& ijk, double t0, double t1) {
                        if (ijk != current) {
                            flush();
                            current = ijk;
                        }
                        pending.add(t, tt, float((t1 - t0) * len));
                    });
                }
                pa = pb;
                ia = ib;
            }
        }
        flush();
    };
    if (threaded) {
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nChunks, 1), [&](const tbb::blocked_range<std::size_t>& r) {
            for (std::size_t c = r.begin(); c != r.end(); ++c) accumulateChunk(c);
        });
    } else {
        for (std::size_t c = 0; c < nChunks; ++c) accumulateChunk(c);
    }
    if (interrupter && interrupter->wasInterrupted()) throw InterruptedError("estimateTangentField: interrupted");

    // Topology: every block any chunk touched, as leaves of the output trees.
    openvdb::Vec3STree::Ptr tangentTree(new openvdb::Vec3STree(openvdb::Vec3f(0.f)));
    openvdb::FloatTree::Ptr densityTree(new openvdb::FloatTree(0.f));
    for (const Chunk& c : chunks) {
        for (const Coord& origin : c.origins) {
            tangentTree->touchLeaf(origin);
            densityTree->touchLeaf(origin);
        }
    }

    // Per leaf: merge the chunks in order, then Eq. 9 and the density.
    openvdb::tree::LeafManager<openvdb::Vec3STree> leaves(*tangentTree);
    leaves.foreach([&](openvdb::Vec3STree::LeafNodeType& leaf, std::size_t) {
        std::array<Moments, 512> sum{};
        std::array<bool, 512> hit{};
        for (const Chunk& c : chunks) {
            const Chunk::Block* block = c.find(leaf.origin());
            if (!block) continue;
            for (int k = 0; k < 512; ++k) {
                if (block->slot[k] == Chunk::kEmpty) continue;
                sum[std::size_t(k)].add(c.moments[block->slot[k]]);
                hit[std::size_t(k)] = true;
            }
        }
        auto* dl = densityTree->probeLeaf(leaf.origin());
        for (openvdb::Index k = 0; k < 512; ++k) {
            if (!hit[k]) continue;
            const Moments& mo = sum[k];
            leaf.setValueOn(k, robustDirection(mo, p.iterations));
            dl->setValueOn(k, mo.m[0] + mo.m[1] + mo.m[2]);
        }
    }, threaded);

    TangentField out;
    out.tangent = openvdb::Vec3SGrid::create(tangentTree);
    out.density = openvdb::FloatGrid::create(densityTree);
    out.tangent->setTransform(map.transform().copy());
    out.density->setTransform(map.transform().copy());
    out.tangent->setName(tangentGridName(level, levels));
    out.density->setName(densityGridName(level, levels));
    out.tangent->setGridClass(openvdb::GRID_UNKNOWN);
    // World-space grids hold world directions that move with the transform's Jacobian
    // (contravariant relative, like velocity); scalp-space grids hold world directions on a
    // (u, v, w) lattice, which the lattice's transform does not act on (invariant).
    out.tangent->setVectorType(p.space == FieldSpace::Scalp ? openvdb::VEC_INVARIANT : openvdb::VEC_CONTRAVARIANT_RELATIVE);
    out.density->setGridClass(openvdb::GRID_FOG_VOLUME);
    for (openvdb::GridBase* g : {static_cast<openvdb::GridBase*>(out.tangent.get()), static_cast<openvdb::GridBase*>(out.density.get())}) {
        setFieldMetadata(*g, voxelSize, p.iterations, p.space, p.scalp, level, levels, strands.numStrands());
    }
    return out;
}

} // namespace

std::uint64_t estimateVoxelVisits(const StrandSet& strands, const FieldParams& params)
{
    checkParams(strands, params, "estimateVoxelVisits");
    return visitBound(strands, mappingFor(params, params.voxelSize));
}

TangentField estimateTangentField(const StrandSet& strands, const FieldParams& params, bool threaded,
                                  openvdb::util::NullInterrupter* interrupter)
{
    checkParams(strands, params, "estimateTangentField");
    return estimateLevel(strands, params, params.voxelSize, 0, 1, threaded, interrupter);
}

std::vector<TangentField> estimateTangentFieldLevels(const StrandSet& strands, const FieldParams& params, int levels,
                                                     bool threaded, openvdb::util::NullInterrupter* interrupter)
{
    checkParams(strands, params, "estimateTangentField");
    if (levels < 1 || levels > 16) throw ValueError("estimateTangentField: levels " + std::to_string(levels) + " must be between 1 and 16");
    std::vector<TangentField> out;
    for (int l = 0; l < levels; ++l) {
        out.push_back(estimateLevel(strands, params, params.voxelSize * double(1 << l), l, levels, threaded, interrupter));
    }
    return out;
}

} // namespace vdbhair
