#include "TangentField.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/field/FieldMapping.h>
#include <vdbhair/field/SegmentWalk.h>

#include <openvdb/tree/LeafManager.h>
#include <openvdb/tree/ValueAccessor.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <array>
#include <cmath>
#include <limits>

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

    void add(const Vec3d& t, double len)
    {
        const float l = float(len), x = float(t.x()), y = float(t.y()), z = float(t.z());
        s[0] += l * x; s[1] += l * y; s[2] += l * z;
        m[0] += l * x * x; m[1] += l * y * y; m[2] += l * z * z;
        m[3] += l * x * y; m[4] += l * x * z; m[5] += l * y * z;
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

/// The accumulation of one chunk of strands: voxel -> index into its moments.
struct Chunk
{
    openvdb::Int32Tree index{-1};
    std::vector<Moments> moments;
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
    std::vector<Chunk> chunks(nChunks);
    auto accumulateChunk = [&](std::size_t c) {
        Chunk& chunk = chunks[c];
        openvdb::tree::ValueAccessor<openvdb::Int32Tree> acc(chunk.index);
        Coord current(std::numeric_limits<int>::max());
        Moments pending;
        auto flush = [&]() {
            if (pending.empty()) return;
            int idx;
            if (acc.probeValue(current, idx)) {
                chunk.moments[std::size_t(idx)].add(pending);
            } else {
                acc.setValue(current, int(chunk.moments.size()));
                chunk.moments.push_back(pending);
            }
            pending = Moments();
        };
        const std::size_t first = nS * c / nChunks, last = nS * (c + 1) / nChunks;
        for (std::size_t i = first; i < last; ++i) {
            if (interrupter && (i & 255) == 0 && interrupter->wasInterrupted()) return;
            for (std::size_t v = strands.begin(i); v + 1 < strands.end(i); ++v) {
                const Vec3d pa(strands.positions[v]), pb(strands.positions[v + 1]);
                const Vec3d seg = pb - pa;
                const double len = seg.length();
                if (len == 0.0) continue;
                const Vec3d t = seg / len;
                walkSegment(map.worldToIndex(pa), map.worldToIndex(pb), [&](const Coord& ijk, double t0, double t1) {
                    if (ijk != current) {
                        flush();
                        current = ijk;
                    }
                    pending.add(t, (t1 - t0) * len);
                });
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

    // Topology: every voxel any chunk touched.
    openvdb::Int32Tree topology(-1);
    for (const Chunk& c : chunks) topology.topologyUnion(c.index);

    // Per leaf: merge the chunks in order, then Eq. 9 and the density.
    openvdb::Vec3STree::Ptr tangentTree(new openvdb::Vec3STree(topology, openvdb::Vec3f(0.f), openvdb::TopologyCopy()));
    openvdb::FloatTree::Ptr densityTree(new openvdb::FloatTree(topology, 0.f, openvdb::TopologyCopy()));
    openvdb::tree::LeafManager<openvdb::Vec3STree> leaves(*tangentTree);
    leaves.foreach([&](openvdb::Vec3STree::LeafNodeType& leaf, std::size_t) {
        std::array<Moments, openvdb::Vec3STree::LeafNodeType::SIZE> sum{};
        for (const Chunk& c : chunks) {
            const auto* cl = c.index.probeConstLeaf(leaf.origin());
            if (!cl) continue;
            for (auto it = cl->cbeginValueOn(); it; ++it) sum[it.pos()].add(c.moments[std::size_t(*it)]);
        }
        auto* dl = densityTree->probeLeaf(leaf.origin());
        for (auto it = leaf.beginValueOn(); it; ++it) {
            const Moments& mo = sum[it.pos()];
            it.setValue(robustDirection(mo, p.iterations));
            dl->setValueOnly(it.pos(), mo.m[0] + mo.m[1] + mo.m[2]);
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
