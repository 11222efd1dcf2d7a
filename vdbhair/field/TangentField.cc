#include "TangentField.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/Parallel.h>
#include <vdbhair/Progress.h>
#include <vdbhair/Quantile.h>
#include <vdbhair/SegmentWalk.h>
#include <vdbhair/field/FieldMapping.h>
#include <vdbhair/field/Refine.h>
#include <vdbhair/field/Simd.h>
#include <vdbhair/field/impl/FieldMoments.h>
#include <vdbhair/strands/Measures.h>

#include <openvdb/tree/LeafManager.h>
#include <openvdb/tree/ValueAccessor.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <memory>
#include <type_traits>
#include <utility>

namespace vdbhair {

namespace {

using openvdb::Coord;
using openvdb::Vec3d;
using field_moments::Chunk;
using field_moments::ChunkWriter;
using field_moments::Moments;
using field_moments::SegmentAccumulator;
using field_moments::coherenceOf;
using field_moments::robustDirection;
using field_moments::spreadOf;

/// Strands are split into this many chunks whatever the thread count (determinism).
std::size_t chunkCount(std::size_t strands) { return std::min<std::size_t>(16, std::max<std::size_t>(1, strands / 256)); }

void checkParams(const StrandSet& strands, const FieldParams& p, const char* where)
{
    if (strands.empty()) throw ValueError(std::string(where) + ": the hairstyle has no strands");
    if (!(p.voxelSize > 0.0) || !std::isfinite(p.voxelSize)) {
        throw ValueError(std::string(where) + ": voxel size " + std::to_string(p.voxelSize) +
                         " must be a positive finite length (0 picks suggestVoxelSize())");
    }
    if (p.densityReference < 0.0 || !std::isfinite(p.densityReference)) {
        throw ValueError(std::string(where) + ": density reference " + std::to_string(p.densityReference) +
                         " must be a positive hair length per unit volume (0 chooses it)");
    }
    // OpenVDB refuses transforms whose scale determinant is within 1e-15 of zero.
    const double lattice = p.space == FieldSpace::Scalp ? p.voxelSize / p.scalpSphere().radius : p.voxelSize;
    if (lattice < 2e-5) {
        throw ValueError(std::string(where) + ": voxel size " + std::to_string(p.voxelSize) +
                         " is below OpenVDB's smallest voxel size (about 2e-5" +
                         (p.space == FieldSpace::Scalp ? " of the scalp radius" : " world units") +
                         "); use a larger voxel or scale the hairstyle up");
    }
    if (p.iterations < 1) throw ValueError(std::string(where) + ": iterations " + std::to_string(p.iterations) + " must be at least 1");
    if (p.space == FieldSpace::Scalp && !(p.scalpSphere().radius > 0.0)) {
        throw ValueError(std::string(where) + ": scalp radius " + std::to_string(p.scalpSphere().radius) + " must be positive");
    }
}

/// The grid transform and the world-to-index mapping of one level.
FieldMapping mappingFor(const FieldParams& p, double voxelSize)
{
    if (p.space == FieldSpace::Scalp) {
        // (u, v, w) voxel size: the world voxel size at the scalp, in units of the radius.
        const auto xform = openvdb::math::Transform::createLinearTransform(voxelSize / p.scalpSphere().radius);
        if (p.scalpSurface) return FieldMapping(xform, p.scalpSurface);
        return FieldMapping(xform, p.scalp);
    }
    return FieldMapping(openvdb::math::Transform::createLinearTransform(voxelSize));
}

/// World to index space for one vertex: the axis-aligned linear map inline, else the mapping.
struct AxisAlignedToIndex
{
    Vec3d offset, invScale;
    Vec3d operator()(const Vec3f& p) const { return (Vec3d(p) - offset) * invScale; }
};
struct MappedToIndex
{
    const FieldMapping& map;
    Vec3d operator()(const Vec3f& p) const { return map.worldToIndex(Vec3d(p)); }
};

/// Call @a fn with the cheapest world-to-index functor for @a map (same results either way).
template<typename Fn>
void withToIndex(const FieldMapping& map, Fn&& fn)
{
    if (map.isAxisAlignedWorld()) fn(AxisAlignedToIndex{map.offset(), map.invScale()});
    else fn(MappedToIndex{map});
}

/// The bounding box of the vertices and the voxel visit bound, in one pass (parallel when threaded).
struct Extent
{
    BBox box;
    bool nan = false;  ///< some coordinate is not a number (the box leaves it out)
    std::uint64_t visits = 0;
};

/// Voxel visit bounds saturate here (beyond any cap).
constexpr std::uint64_t kSaturated = std::uint64_t(1) << 62;

Extent measure(const StrandSet& strands, const FieldMapping& map, bool threaded)
{
    Extent result;
    withToIndex(map, [&](const auto& toIndex) {
        // Min, max and integer sums: the same result however the range is split.
        const tbb::blocked_range<std::size_t> all(0, strands.numStrands(), 256);
        const auto extend = [&](const tbb::blocked_range<std::size_t>& r, Extent e) {
            Float4 lo = loadFloat3(e.box.min.asPointer()), hi = loadFloat3(e.box.max.asPointer());
            Int4 nan = {0, 0, 0, 0};
            for (std::size_t i = r.begin(); i != r.end(); ++i) {
                const Vec3f* v = strands.data(i);
                const std::size_t n = strands.size(i);
                Vec3d a = toIndex(v[0]);
                for (std::size_t j = 0; j < n; ++j) {
                    const Float4 p = loadFloat3(v[j].asPointer());
                    lo = p < lo ? p : lo;
                    hi = p > hi ? p : hi;
                    nan |= p != p;
                    if (j == 0 || e.visits > kSaturated) continue;
                    const Vec3d b = toIndex(v[j]);
                    e.visits += segmentVoxelBound(a, b);
                    a = b;
                }
            }
            e.box.min = Vec3f(lo[0], lo[1], lo[2]);
            e.box.max = Vec3f(hi[0], hi[1], hi[2]);
            e.nan = e.nan || any(nan);
            return e;
        };
        const auto join = [](Extent a, const Extent& b) {
            a.box.expand(b.box.min);
            a.box.expand(b.box.max);
            a.nan = a.nan || b.nan;
            a.visits = std::min(a.visits + b.visits, kSaturated);
            return a;
        };
        result = threaded ? tbb::parallel_reduce(all, Extent(), extend, join) : extend(all, Extent());
    });
    return result;
}

/// Index coordinates must fit OpenVDB's int32 Coord (and the block count's arithmetic).
void checkIndexRange(Extent extent, const FieldMapping& map, double voxelSize)
{
    if (extent.nan) extent.box.min = Vec3f(std::numeric_limits<float>::quiet_NaN());  // fails below
    for (const Vec3f& corner : {extent.box.min, extent.box.max}) {
        const Vec3d ip = map.worldToIndex(Vec3d(corner));
        for (int k = 0; k < 3; ++k) {
            if (!(std::abs(ip[k]) < double(1 << 30))) {
                throw LimitError("estimateTangentField: voxel size " + std::to_string(voxelSize) +
                                 " puts the hairstyle at index " + std::to_string(ip[k]) +
                                 ", beyond the grid's index range of ±2^30");
            }
        }
    }
}

/// The maxVoxels rule: LimitError above the cap.
void checkVisits(std::uint64_t bound, const FieldParams& p, double voxelSize)
{
    if (bound > p.maxVoxels) {
        throw ParamError<LimitError>({"estimateTangentField: voxel size " + std::to_string(voxelSize) + " needs up to " +
                                          std::to_string(bound) + " voxel visits, more than the cap of " + std::to_string(p.maxVoxels) + " (raise ",
                                      paramName(fieldParameters(), "max-voxels"), " or the voxel size)"});
    }
}

/// Bounding boxes of at most this many leaf blocks are counted block by block (a bit each).
constexpr std::uint64_t kMaxCountedBlocks = std::uint64_t(1) << 27;

/// @brief The 8^3 leaf blocks the segments of @a strands pass through (what the accumulation
/// touches: the leaves of every grid), counted with a bit per block of the index bounding box;
/// min(@a visits, blocks of the box) when the box has more than kMaxCountedBlocks blocks.
/// @a extent is measure()'s of the same strands and map. Unless @a exact, only the box is found
/// and min(@a visits, blocks of the box) returned: a bound on the count, without the walk.
std::uint64_t countLeaves(const StrandSet& strands, const FieldMapping& map, std::uint64_t visits, const Extent& extent,
                          bool exact = true)
{
    const std::size_t nS = strands.numStrands();
    struct Box
    {
        Coord lo{std::numeric_limits<int>::max()}, hi{std::numeric_limits<int>::min()};
    };
    Box box;
    const auto blockOf = [](const Coord& c) { return Coord(c.x() >> 3, c.y() >> 3, c.z() >> 3); };
    if (map.isAxisAlignedWorld() && map.invScale().x() > 0.0 && map.invScale().y() > 0.0 && map.invScale().z() > 0.0) {
        // Each index coordinate grows with its world coordinate alone (a difference and a positive
        // factor, then floor: every step rounds monotonically), so the blocks' box is that of the
        // vertices' box corners: no pass over the vertices.
        if (extent.box.empty()) return 0;
        const AxisAlignedToIndex toIndex{map.offset(), map.invScale()};
        box.lo = blockOf(voxelOf(toIndex(extent.box.min)));
        box.hi = blockOf(voxelOf(toIndex(extent.box.max)));
    } else {
        withToIndex(map, [&](const auto& toIndex) {
            box = tbb::parallel_reduce(
                tbb::blocked_range<std::size_t>(0, nS, 256), Box(),
                [&](const tbb::blocked_range<std::size_t>& r, Box b) {
                    for (std::size_t i = r.begin(); i != r.end(); ++i) {
                        const Vec3f* v = strands.data(i);
                        for (std::size_t j = 0, n = strands.size(i); j < n; ++j) {
                            const Coord blk = blockOf(voxelOf(toIndex(v[j])));
                            b.lo.minComponent(blk);
                            b.hi.maxComponent(blk);
                        }
                    }
                    return b;
                },
                [](Box a, const Box& b) {
                    a.lo.minComponent(b.lo);
                    a.hi.maxComponent(b.hi);
                    return a;
                });
        });
    }
    if (box.lo.x() > box.hi.x()) return 0;
    const std::uint64_t nx = std::uint64_t(box.hi.x() - box.lo.x()) + 1, ny = std::uint64_t(box.hi.y() - box.lo.y()) + 1,
                        nz = std::uint64_t(box.hi.z() - box.lo.z()) + 1;
    const double boxBlocks = double(nx) * double(ny) * double(nz);
    if (!exact || boxBlocks > double(kMaxCountedBlocks)) return std::min<std::uint64_t>(visits, std::uint64_t(std::min(boxBlocks, 1e18)));
    std::vector<std::uint64_t> bits((nx * ny * nz + 63) / 64, 0);
    withToIndex(map, [&](const auto& toIndex) {
        // Walk each segment through the blocks: block b spans index [8b - 0.5, 8b + 7.5), so the
        // affine map x -> (x + 0.5) / 8 - 0.5 turns blocks into the unit cells of walkSegment().
        const auto toBlock = [](const Vec3d& x) { return (x + Vec3d(0.5)) * 0.125 - Vec3d(0.5); };
        const auto mark = [&](const Coord& b) {
            const std::uint64_t k = (std::uint64_t(b.x() - box.lo.x()) * ny + std::uint64_t(b.y() - box.lo.y())) * nz +
                                    std::uint64_t(b.z() - box.lo.z());
            std::uint64_t& word = bits[k >> 6];
            const std::uint64_t bit = std::uint64_t(1) << (k & 63);
            if (!(__atomic_load_n(&word, __ATOMIC_RELAXED) & bit)) __atomic_fetch_or(&word, bit, __ATOMIC_RELAXED);
        };
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nS, 256), [&](const tbb::blocked_range<std::size_t>& r) {
            for (std::size_t i = r.begin(); i != r.end(); ++i) {
                const Vec3f* v = strands.data(i);
                const std::size_t n = strands.size(i);
                if (n == 0) continue;
                Vec3d a = toBlock(toIndex(v[0]));
                Coord ca = voxelOf(a);
                for (std::size_t j = 1; j < n; ++j) {
                    const Vec3d b = toBlock(toIndex(v[j]));
                    const Coord cb = voxelOf(b);
                    if (v[j] != v[j - 1]) {  // zero-length segments add nothing (SegmentAccumulator)
                        if (ChunkWriter::sameCoord(ca, cb)) mark(ca);
                        else walkSegment(a, b, ca, cb, [&](const Coord& c, double, double) { mark(c); });
                    }
                    a = b;
                    ca = cb;
                }
            }
        });
    });
    std::uint64_t count = 0;
    for (std::uint64_t w : bits) count += std::uint64_t(__builtin_popcountll(w));
    return count;
}

std::uint64_t visitBound(const StrandSet& strands, const FieldMapping& map)
{
    return std::min(measure(strands, map, true).visits, kSaturated);
}

/// The strands' extent at a level and their spatial order: chunks of neighbouring strands share
/// voxels, so a chunk's moments stay small and in cache. @a measured is the extent when the
/// memory check took it already.
void measureAndOrder(const StrandSet& strands, const FieldMapping& map, bool threaded, const Extent* measured, Extent& extent,
                     std::vector<std::uint32_t>& order)
{
    if (measured) {
        extent = *measured;
        order = spatialOrder(strands);
    } else if (threaded) {
        tbb::parallel_invoke([&] { extent = measure(strands, map, true); }, [&] { order = spatialOrder(strands); });
    } else {
        extent = measure(strands, map, false);
        order = spatialOrder(strands);
    }
}

/// The moments of every voxel the strands cross, chunk by chunk (each chunk in strand order).
std::vector<Chunk> accumulateChunks(const StrandSet& strands, const std::vector<std::uint32_t>& order, const FieldMapping& map,
                                    bool threaded, openvdb::util::NullInterrupter* interrupter, const std::string& stage)
{
    const std::size_t nS = strands.numStrands(), nChunks = chunkCount(nS);
    std::vector<Chunk> chunks(nChunks);
    ProgressCounter progress(interrupter, stage.c_str(), nS, "strands");
    withToIndex(map, [&](const auto& toIndex) {
        auto accumulateChunk = [&](std::size_t c) {
            SegmentAccumulator<std::decay_t<decltype(toIndex)>> acc(chunks[c], toIndex);
            const std::size_t first = nS * c / nChunks, last = nS * (c + 1) / nChunks;
            std::size_t counted = first;  // strands reported so far end here
            for (std::size_t o = first; o < last; ++o) {
                if (progress.active() && o - counted == 256) {  // report every 256 strands
                    counted = o;
                    if (progress.add(256)) return;
                }
                // The spatial order scatters strands over memory: fetch a later one meanwhile.
                if (o + 2 < last) prefetchBytes(strands.data(order[o + 2]), strands.size(order[o + 2]) * sizeof(Vec3f));
                const std::size_t i = order[o];
                acc.addStrand(strands.data(i), strands.size(i));
            }
            acc.flush();
            progress.add(last - counted);
        };
        if (threaded) {
            tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nChunks, 1), [&](const tbb::blocked_range<std::size_t>& r) {
                for (std::size_t c = r.begin(); c != r.end(); ++c) accumulateChunk(c);
            });
        } else {
            for (std::size_t c = 0; c < nChunks; ++c) accumulateChunk(c);
        }
    });
    progress.finish();
    if (progress.stopped()) throw InterruptedError("estimateTangentField: interrupted");
    return chunks;
}

/// The trees of one level: the tangent tree's leaves are every block any chunk touched; the
/// scalar trees copy its topology.
struct LevelTrees
{
    openvdb::Vec3STree::Ptr tangent;
    openvdb::FloatTree::Ptr density, coherence, spread;  ///< coherence and spread when asked for
};

/// The topology of a level. The leaves are made in parallel (each fills its buffer: fresh pages,
/// which the threads then fault in together) and then linked into the tree, which is what
/// touchLeaf() would make; the other trees copy it in parallel (OpenVDB's topology copy).
LevelTrees makeLevelTopology(const std::vector<Chunk>& chunks, bool extra, bool threaded)
{
    LevelTrees trees;
    trees.tangent.reset(new openvdb::Vec3STree(openvdb::Vec3f(0.f)));
    {
        using LeafT = openvdb::Vec3STree::LeafNodeType;
        std::vector<Coord> origins;
        for (const Chunk& c : chunks) origins.insert(origins.end(), c.origins.begin(), c.origins.end());
        std::sort(origins.begin(), origins.end());
        origins.erase(std::unique(origins.begin(), origins.end()), origins.end());
        std::vector<std::unique_ptr<LeafT>> made(origins.size());
        const auto make = [&](std::size_t i) { made[i].reset(new LeafT(origins[i], openvdb::Vec3f(0.f), false)); };
        forEachIndex(origins.size(), threaded, make);
        for (std::unique_ptr<LeafT>& leaf : made) trees.tangent->addLeaf(leaf.release());  // the tree owns it from here
    }
    const auto copyTopology = [&](openvdb::FloatTree::Ptr& tree) {
        tree.reset(new openvdb::FloatTree(*trees.tangent, 0.f, openvdb::TopologyCopy()));
    };
    if (threaded && extra) {
        tbb::parallel_invoke([&] { copyTopology(trees.density); }, [&] { copyTopology(trees.coherence); },
                             [&] { copyTopology(trees.spread); });
    } else {
        copyTopology(trees.density);
        if (extra) copyTopology(trees.coherence);
        if (extra) copyTopology(trees.spread);
    }
    return trees;
}

/// Per leaf: merge the chunks' moments in chunk order, then Eq. 9's direction, the raw density
/// (hair length) and, when asked for, coherence and spread.
void solveDirections(LevelTrees& trees, const std::vector<Chunk>& chunks, int iterations, bool extra, bool threaded,
                     openvdb::util::NullInterrupter* interrupter, const std::string& stage)
{
    openvdb::tree::LeafManager<openvdb::Vec3STree> leaves(*trees.tangent);
    ProgressCounter directions(interrupter, (stage + ": robust directions (Eq. 9)").c_str(), leaves.leafCount(), "blocks");
    leaves.foreach([&](openvdb::Vec3STree::LeafNodeType& leaf, std::size_t) {
        if (directions.active() && (directions.stopped() || directions.add(1))) return;
        std::array<Moments, 512> sum;
        std::array<bool, 512> hit{};
        for (const Chunk& c : chunks) {
            const Chunk::Block* block = c.find(leaf.origin());
            if (!block) continue;
            for (int k = 0; k < 512; ++k) {
                if (block->slot[k] == Chunk::kEmpty) continue;
                if (hit[std::size_t(k)]) {
                    sum[std::size_t(k)].add(c.moments[block->slot[k]]);
                } else {
                    sum[std::size_t(k)] = c.moments[block->slot[k]];
                    hit[std::size_t(k)] = true;
                }
            }
        }
        auto* dl = trees.density->probeLeaf(leaf.origin());
        auto* cl = extra ? trees.coherence->probeLeaf(leaf.origin()) : nullptr;
        auto* sl = extra ? trees.spread->probeLeaf(leaf.origin()) : nullptr;
        for (openvdb::Index k = 0; k < 512; ++k) {
            if (!hit[k]) continue;
            const Moments& mo = sum[k];
            const openvdb::Vec3f v = robustDirection(mo, iterations);
            leaf.setValueOn(k, v);
            dl->setValueOn(k, mo.density());
            if (!extra) continue;
            cl->setValueOn(k, coherenceOf(mo));
            sl->setValueOn(k, spreadOf(mo, v));
        }
    }, threaded);
    if (directions.stopped()) throw InterruptedError("estimateTangentField: interrupted");
}

/// The density reference (hair length per unit volume): @a given when positive, else the 95th
/// percentile of the raw density over the voxel volume.
double densityReferenceOf(const openvdb::FloatTree& density, double given, double voxelVolume, bool threaded)
{
    double reference = given;
    if (reference > 0.0) return reference;
    // The active values (all in leaves: the trees are built leaf by leaf), gathered leaf by
    // leaf in parallel; the percentile does not depend on their order.
    openvdb::tree::LeafManager<const openvdb::FloatTree> dleaves(density);
    std::vector<std::size_t> start(dleaves.leafCount() + 1, 0);
    for (std::size_t i = 0; i < dleaves.leafCount(); ++i) start[i + 1] = start[i] + dleaves.leaf(i).onVoxelCount();
    std::vector<float> values(start.back());
    forEachIndex(dleaves.leafCount(), threaded, [&](std::size_t i) {
        std::size_t k = start[i];
        for (auto it = dleaves.leaf(i).cbeginValueOn(); it; ++it) values[k++] = *it;
    });
    if (!values.empty()) {
        // The order statistic floor(0.95 n) (within the sample).
        const std::size_t k = std::size_t(0.95 * double(values.size()));
        reference = double(orderStatistic(std::move(values), k)) / voxelVolume;
    }
    if (!(reference > 0.0)) reference = 1.0 / voxelVolume;
    return reference;
}

/// Density as a fog volume: min(1, raw / (voxel volume × reference)) (TangentField.h states the rule).
void normalizeDensity(openvdb::FloatTree& density, double voxelVolume, double reference, bool threaded)
{
    const float scale = float(1.0 / (voxelVolume * reference));
    openvdb::tree::LeafManager<openvdb::FloatTree> dleaves(density);
    dleaves.foreach([scale](openvdb::FloatTree::LeafNodeType& leaf, std::size_t) {
        for (auto it = leaf.beginValueOn(); it; ++it) it.setValue(std::min(1.f, *it * scale));
    }, threaded);
}

/// The level's grids from its trees: names, classes, vector type, transform and metadata.
void nameAndDescribeGrids(TangentField& out, const LevelTrees& trees, const FieldParams& p, const FieldMapping& map,
                          double voxelSize, int level, int levels, std::size_t numStrands)
{
    out.tangent = openvdb::Vec3SGrid::create(trees.tangent);
    out.density = openvdb::FloatGrid::create(trees.density);
    out.tangent->setName(tangentGridName(level, levels));
    out.density->setName(densityGridName(level, levels));
    if (trees.coherence) {
        out.coherence = openvdb::FloatGrid::create(trees.coherence);
        out.spread = openvdb::FloatGrid::create(trees.spread);
        out.coherence->setName(coherenceGridName(level, levels));
        out.spread->setName(spreadGridName(level, levels));
    }
    out.tangent->setGridClass(openvdb::GRID_UNKNOWN);
    // World-space grids hold world directions that move with the transform's Jacobian
    // (contravariant relative, like velocity); scalp-space grids hold world directions on a
    // (u, v, w) lattice, which the lattice's transform does not act on (invariant).
    out.tangent->setVectorType(p.space == FieldSpace::Scalp ? openvdb::VEC_INVARIANT : openvdb::VEC_CONTRAVARIANT_RELATIVE);
    out.density->setGridClass(openvdb::GRID_FOG_VOLUME);
    out.hairLength->setName(hairLengthGridName(level, levels));
    out.hairLength->setGridClass(openvdb::GRID_UNKNOWN);
    for (openvdb::GridBase* g : {static_cast<openvdb::GridBase*>(out.tangent.get()), static_cast<openvdb::GridBase*>(out.density.get()),
                                 static_cast<openvdb::GridBase*>(out.hairLength.get()), static_cast<openvdb::GridBase*>(out.coherence.get()),
                                 static_cast<openvdb::GridBase*>(out.spread.get())}) {
        if (!g) continue;  // coherence and spread when not asked for
        g->setTransform(map.transform().copy());
        setFieldMetadata(*g, voxelSize, p.iterations, p.space, map.scalp(), level, levels, numStrands, map.scalpSurface().get());
    }
    out.density->insertMeta("vdbhair_density_reference", openvdb::DoubleMetadata(out.densityReference));
    out.density->insertMeta("vdbhair_density_rule", openvdb::StringMetadata(
        "min(1, hair_length / (voxel_size^3 * vdbhair_density_reference)): hair length per unit volume over the reference"));
}

/// @param measured measure()'s extent of @a strands at @a voxelSize when the memory check took it
/// already (checkFieldMemory()), or null
TangentField estimateLevel(const StrandSet& strands, const FieldParams& p, double voxelSize, int level, int levels,
                           bool threaded, openvdb::util::NullInterrupter* interrupter, const Extent* measured = nullptr)
{
    const FieldMapping map = mappingFor(p, voxelSize);

    // Bounds before any allocation: index coordinates must fit OpenVDB's int32 Coord, and the
    // voxel visits the cap.
    Extent extent;
    std::vector<std::uint32_t> order;
    measureAndOrder(strands, map, threaded, measured, extent, order);
    checkIndexRange(extent, map, voxelSize);
    checkVisits(std::min(extent.visits, kSaturated), p, voxelSize);

    const std::string stage = levels > 1 ? "estimating level " + std::to_string(level) + " of " + std::to_string(levels)
                                         : std::string("estimating the tangent field");
    const std::vector<Chunk> chunks = accumulateChunks(strands, order, map, threaded, interrupter, stage);
    LevelTrees trees = makeLevelTopology(chunks, p.coherenceAndSpread, threaded);
    solveDirections(trees, chunks, p.iterations, p.coherenceAndSpread, threaded, interrupter, stage);

    // The raw sums as hair_length; density normalized to a fog volume.
    TangentField out;
    out.hairLength = openvdb::FloatGrid::create(openvdb::FloatTree::Ptr(new openvdb::FloatTree(*trees.density)));
    const double voxelVolume = voxelSize * voxelSize * voxelSize;
    out.densityReference = densityReferenceOf(*trees.density, p.densityReference, voxelVolume, threaded);
    normalizeDensity(*trees.density, voxelVolume, out.densityReference, threaded);
    nameAndDescribeGrids(out, trees, p, map, voxelSize, level, levels, strands.numStrands());
    return out;
}

} // namespace

openvdb::GridCPtrVec TangentField::grids() const
{
    openvdb::GridCPtrVec out;
    for (const openvdb::GridBase::ConstPtr& g : {openvdb::GridBase::ConstPtr(tangent), openvdb::GridBase::ConstPtr(density),
                                                 openvdb::GridBase::ConstPtr(hairLength), openvdb::GridBase::ConstPtr(coherence),
                                                 openvdb::GridBase::ConstPtr(spread)}) {
        if (g) out.push_back(g);
    }
    return out;
}

double resolveVoxelSize(const StrandSet& strands, const FieldParams& params)
{
    return params.voxelSize == 0.0 ? suggestVoxelSize(strands) : params.voxelSize;
}

namespace {

/// @a params with the voxel size resolved (resolveVoxelSize()) and checked (checkParams()).
FieldParams resolvedParams(const StrandSet& strands, const FieldParams& params, const char* where)
{
    FieldParams p = params;
    if (!strands.empty()) p.voxelSize = resolveVoxelSize(strands, params);
    checkParams(strands, p, where);
    return p;
}

/// estimateFieldFootprint(), and the extent it measured in @a extent; unless @a exactLeaves, the
/// leaves are countLeaves()'s bound.
FieldFootprint footprintOf(const StrandSet& strands, const FieldParams& params, Extent& extent, bool exactLeaves)
{
    const FieldParams p = resolvedParams(strands, params, "estimateTangentField");
    const FieldMapping map = mappingFor(p, p.voxelSize);
    FieldFootprint f;
    f.strands = strands.numStrands();
    f.vertices = strands.numVertices();
    extent = measure(strands, map, true);
    checkIndexRange(extent, map, p.voxelSize);  // as estimateTangentField() does, before counting
    f.visits = std::min(extent.visits, kSaturated);
    checkVisits(f.visits, p, p.voxelSize);  // also bounds the walk of countLeaves()
    f.leaves = countLeaves(strands, map, f.visits, extent, exactLeaves);
    return f;
}

/// Each level's leaves from level @a first on, counted exactly (countLeaves()'s walk) over the
/// extents measured for the bound.
void countLeavesExactly(const StrandSet& strands, const FieldParams& p, std::vector<FieldFootprint>& footprints,
                        const std::vector<Extent>& extents, std::size_t first)
{
    FieldParams lp = p;
    for (std::size_t l = first; l < footprints.size(); ++l) {
        FieldFootprint& f = footprints[l];
        lp.voxelSize = p.voxelSize * double(1 << l);
        f.leaves = countLeaves(strands, mappingFor(lp, lp.voxelSize), f.visits, extents[l]);
    }
}

/// The levels rule of the multi-level estimates: ValueError naming @a where outside [1, FieldParams::kMaxLevels].
void checkLevels(int levels, const char* where)
{
    if (levels < 1 || levels > FieldParams::kMaxLevels) {
        throw ParamError<ValueError>({std::string(where) + ": ", paramName(refineParameters(), "levels"),
                                      " " + std::to_string(levels) + " must be between 1 and " + std::to_string(FieldParams::kMaxLevels)});
    }
}

/// Refuse a @a use of @a levels levels at @a p (voxel size resolved) whose estimate exceeds the
/// memory it may use (the message names @a where); nothing is counted when there is no limit
/// (maxMemory at its largest) and @a footprintsOut is null.
/// @param footprintsOut if not null, receives the footprints checked, and @a exactOut whether
/// their leaves are exact (else countLeaves()'s bound, which was enough for the check)
/// @return each level's extent, as estimateLevel() measures it, when they were measured; else empty
std::vector<Extent> checkFieldMemory(const StrandSet& strands, const FieldParams& p, int levels, MemoryUse use = MemoryUse::Field,
                                     const char* where = "estimateTangentField",
                                     std::vector<FieldFootprint>* footprintsOut = nullptr, bool* exactOut = nullptr)
{
    if (!footprintsOut && p.maxMemory == std::numeric_limits<std::uint64_t>::max()) return {};
    std::vector<FieldFootprint> footprints;
    std::vector<Extent> extents(static_cast<std::size_t>(levels));
    FieldParams lp = p;
    for (int l = 0; l < levels; ++l) {
        lp.voxelSize = p.voxelSize * double(1 << l);
        footprints.push_back(footprintOf(strands, lp, extents[std::size_t(l)], /*exactLeaves=*/false));
    }
    // The leaves bounded by their box first: the estimate grows with them, so when the bound fits,
    // so does the exact count, and the walk of every segment that counts them (7 % of `field`'s
    // CPU) is only taken for a request that may not fit, whose message names the exact count.
    bool exact = false;
    if (estimatePeakBytes(footprints, use) > availableMemoryBytes(p)) {
        countLeavesExactly(strands, p, footprints, extents, 0);
        exact = true;
    }
    std::uint64_t leaves = 0;
    for (const FieldFootprint& f : footprints) leaves += f.leaves;
    const std::string counts = std::to_string(strands.numStrands()) + " strands, " + std::to_string(strands.numVertices()) +
                               " vertices, " + std::to_string(leaves) + " leaves";
    checkMemoryEstimate(where, estimatePeakBytes(footprints, use),
                        counts + (use == MemoryUse::Refine ? " in " + std::to_string(levels) + " level(s) from voxel size "
                                                           : std::string(" at voxel size ")) +
                            std::to_string(p.voxelSize),
                        p);
    if (footprintsOut) *footprintsOut = std::move(footprints);
    if (exactOut) *exactOut = exact;
    return extents;
}

} // namespace

FieldFootprint estimateFieldFootprint(const StrandSet& strands, const FieldParams& params)
{
    Extent extent;
    return footprintOf(strands, params, extent, /*exactLeaves=*/true);
}

namespace {

/// The memory model's terms (bytes), fitted to the peak resident memory of `vdbhair field` and
/// `vdbhair refine` (docs/performance.md, "Memory at scale": 100,000 strands at three voxel sizes and with 3
/// levels, 250,000 and 500,000 strands, x 32 vertices) so that the estimate stays above every
/// measured peak, by 4-19 %. Per leaf: a leaf's cost depends on how many of its 512 voxels the
/// hair fills, which is not known before the estimate, so the fit takes the larger of the
/// measured slopes.
namespace memory {
constexpr std::uint64_t kBase = std::uint64_t(48) << 20;  ///< the process: libraries, allocator arenas, threads
constexpr std::uint64_t kStrand = 8;                      ///< a strand's offset and its place in the spatial order
constexpr std::uint64_t kStrandVertex = 12;               ///< one copy of the positions
/// field, per vertex: the strands (12) and what reading them leaves behind
constexpr std::uint64_t kFieldVertex = 18;
constexpr std::uint64_t kFieldLeaf = 15 << 10;  ///< a kept level's five grids: 512 x (12 + 4 x 4) bytes and masks
constexpr std::uint64_t kChunkLeaf = 25 << 10;  ///< the chunks (slots and moments) of the level being estimated
/// refine, the rest of the process: the head's fit, the report's k-d tree and scratch
constexpr std::uint64_t kRefineBase = std::uint64_t(32) << 20;
/// refine, per vertex: the input and output strands (24), the report's displacements (4), the
/// writer's bytes (12) while both sets are alive, and the report's per-strand curvatures
constexpr std::uint64_t kRefineVertex = 44;
/// refine, per leaf of every level: the level's grids, the input's field, the chunks, the
/// retrace's bricks and the report's field of the output
constexpr std::uint64_t kRefineLeaf = 83 << 10;
} // namespace memory

} // namespace

std::uint64_t estimatePeakBytes(const std::vector<FieldFootprint>& footprints, MemoryUse use)
{
    if (footprints.empty()) return memory::kBase;
    const FieldFootprint& f0 = footprints.front();
    std::uint64_t leaves = 0, maxLeaves = 0;
    for (const FieldFootprint& f : footprints) {
        leaves += f.leaves;
        maxLeaves = std::max(maxLeaves, f.leaves);
    }
    const std::uint64_t strands = memory::kBase + memory::kStrand * f0.strands;
    if (use == MemoryUse::Field) {
        // Every level's grids are kept; the chunks of one level at a time.
        return strands + memory::kFieldVertex * f0.vertices + memory::kFieldLeaf * leaves + memory::kChunkLeaf * maxLeaves;
    }
    // With more than one level, a level's strands are made while the last level's are alive.
    const std::uint64_t copies = footprints.size() > 1 ? memory::kStrandVertex * f0.vertices : 0;
    return strands + memory::kRefineBase + memory::kRefineVertex * f0.vertices + copies + memory::kRefineLeaf * leaves;
}

std::uint64_t availableMemoryBytes(const FieldParams& params)
{
    return availableMemoryBytes(params.maxMemory);
}

void checkMemoryEstimate(const char* where, std::uint64_t estimate, const std::string& how, const FieldParams& params)
{
    const ParamName maxMemory = paramName(fieldParameters(), "max-memory");
    checkMemory(where, estimate, how,
                {"a request whose estimate exceeds the memory it may use is refused before it allocates (raise ", maxMemory,
                 " or the voxel size, or split the hairstyle)"},
                params.maxMemory, maxMemory);
}

std::uint64_t estimateVoxelVisits(const StrandSet& strands, const FieldParams& params)
{
    const FieldParams p = resolvedParams(strands, params, "estimateVoxelVisits");
    return visitBound(strands, mappingFor(p, p.voxelSize));
}

void useScalpSpace(FieldParams& params, const std::vector<Vec3f>& roots, const Vec3d& up, const ScalpSphere* sphere,
                   openvdb::FloatGrid::ConstPtr surface)
{
    if (sphere && surface) throw ValueError("scalp space: a sphere and a scalp surface were both given; the surface's sphere is fitted to the roots");
    if (sphere && (!(sphere->radius > 0.0) || !std::isfinite(sphere->radius)))
        throw ValueError("scalp space: sphere radius " + std::to_string(sphere->radius) + " must be positive and finite");
    const Vec3d upAxis = up.unitSafe();
    if (upAxis.lengthSqr() == 0.0) throw ValueError("scalp space: the up axis must be a non-zero vector");
    params.space = FieldSpace::Scalp;
    params.scalpSurface.reset();
    if (sphere) {
        params.scalp = *sphere;
        params.scalp.up = upAxis;
    } else if (surface) {
        params.scalpSurface = scalpMapOfPoints(roots, upAxis, surface, nullptr, ScalpMap::kFieldResolution);
        params.scalp = params.scalpSurface->sphere();
    } else {
        params.scalp = fitScalpSphere(roots, upAxis);
    }
}

TangentField estimateTangentField(const StrandSet& strands, const FieldParams& params, bool threaded,
                                  openvdb::util::NullInterrupter* interrupter)
{
    const FieldParams p = resolvedParams(strands, params, "estimateTangentField");
    const std::vector<Extent> extents = checkFieldMemory(strands, p, 1);
    return estimateLevel(strands, p, p.voxelSize, 0, 1, threaded, interrupter, extents.empty() ? nullptr : &extents[0]);
}

TangentField estimateTangentFieldAfterCheck(const StrandSet& strands, const FieldParams& params, MemoryUse use, int levels,
                                            const char* where, std::vector<FieldFootprint>& footprints, bool threaded,
                                            openvdb::util::NullInterrupter* interrupter)
{
    checkLevels(levels, where);
    const FieldParams p = resolvedParams(strands, params, "estimateTangentField");
    bool exact = false;
    const std::vector<Extent> extents = checkFieldMemory(strands, p, levels, use, where, &footprints, &exact);
    TangentField field = estimateLevel(strands, p, p.voxelSize, 0, 1, threaded, interrupter, &extents[0]);
    if (!exact) {
        // The check needed only the bound. Level 0's leaves are the field's own (the blocks its
        // segments pass through, what countLeaves() walks); the coarser levels' are walked.
        footprints[0].leaves = field.tangent->tree().leafCount();
        countLeavesExactly(strands, p, footprints, extents, 1);
    }
    return field;
}

std::vector<TangentField> estimateTangentFieldLevels(const StrandSet& strands, const FieldParams& params, int levels,
                                                     bool threaded, openvdb::util::NullInterrupter* interrupter)
{
    checkLevels(levels, "estimateTangentField");
    FieldParams lp = resolvedParams(strands, params, "estimateTangentField");
    const std::vector<Extent> extents = checkFieldMemory(strands, lp, levels);
    const double voxelSize = lp.voxelSize;
    std::vector<TangentField> out;
    for (int l = 0; l < levels; ++l) {
        out.push_back(estimateLevel(strands, lp, voxelSize * double(1 << l), l, levels, threaded, interrupter,
                                    extents.empty() ? nullptr : &extents[std::size_t(l)]));
        lp.densityReference = out.front().densityReference;  // one meaning for every level
    }
    return out;
}

} // namespace vdbhair
