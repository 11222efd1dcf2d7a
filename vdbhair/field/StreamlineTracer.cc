#include "StreamlineTracer.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/Memory.h>
#include <vdbhair/Progress.h>
#include <vdbhair/field/FieldMapping.h>
#include <vdbhair/field/FieldSampler.h>
#include <vdbhair/field/SamplerRetrace.h>
#include <vdbhair/field/Simd.h>
#include <vdbhair/field/impl/LaneTracer.h>
#include <vdbhair/strands/Measures.h>

#include <openvdb/openvdb.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>
#include <tbb/task_group.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <memory>
#include <numeric>

namespace vdbhair {

using openvdb::Vec3d;

namespace {

using lanes::LaneTracer;
using lanes::RetraceJob;

/// @brief Move each strand's kept prefix down to its final place, in place: strand i's first
/// used[i] vertices go from in.begin(i) to offsets[i] (<= in.begin(i)).
///
/// One pass in strand order (runs of strands that shift alike move in one memmove) is safe,
/// since every destination lies at or below its source and above every earlier destination, but
/// it moves tens of megabytes on one thread. So the strands are cut into @a chunks pieces of
/// about equal size, moved in two phases: first each piece moves, on its own, everything whose
/// destination lies within its own source range (no other piece reads or writes there), and
/// copies aside the head that lands below it — in the sources of earlier pieces, which may not
/// have been read yet; then, once every piece is through, the heads go to their places (the gaps
/// the earlier pieces' moves left). The heads add up to the vertices dropped before each piece.
void compactPrefixes(const StrandSet& in, const std::vector<std::uint32_t>& used, const std::vector<std::uint32_t>& offsets,
                     Vec3f* pos, std::size_t chunks)
{
    const std::size_t nS = in.numStrands();
    chunks = std::max<std::size_t>(1, std::min(chunks, nS));
    std::vector<std::size_t> first(chunks + 1, nS);  // first strand of each piece
    for (std::size_t c = 0, i = 0; c < chunks; ++c) {
        const std::size_t goal = in.numVertices() / chunks * c;
        while (i < nS && in.begin(i) < goal) ++i;
        first[c] = i;
    }
    std::vector<std::vector<Vec3f>> heads(chunks);
    auto movePiece = [&](std::size_t c) {
        const std::size_t a = first[c], b = first[c + 1];
        if (a >= b) return;
        const std::size_t dst0 = offsets[a];
        const std::size_t mine = std::min<std::size_t>(offsets[b], in.begin(a));  // destinations below this go to the head
        heads[c].resize(mine - dst0);
        for (std::size_t i = a; i < b;) {
            const std::size_t from = in.begin(i), to = offsets[i];
            std::size_t j = i + 1;
            while (j < b && used[j - 1] == in.size(j - 1)) ++j;  // strands i+1 .. j-1 shift as strand i
            const std::size_t len = offsets[j] - to;
            const std::size_t toHead = to < mine ? std::min(len, mine - to) : 0;
            if (toHead) std::memcpy(heads[c].data() + (to - dst0), pos + from, toHead * sizeof(Vec3f));
            if (len > toHead && to != from) {
                std::memmove(pos + to + toHead, pos + from + toHead, (len - toHead) * sizeof(Vec3f));
            }
            i = j;
        }
    };
    auto placeHead = [&](std::size_t c) {
        if (!heads[c].empty()) std::memcpy(pos + offsets[first[c]], heads[c].data(), heads[c].size() * sizeof(Vec3f));
    };
    if (chunks == 1) {
        movePiece(0);
        placeHead(0);
        return;
    }
    tbb::parallel_for(std::size_t(0), chunks, movePiece);
    tbb::parallel_for(std::size_t(0), chunks, placeHead);
}

/// Retrace all strands through the tree of a Vec3 grid.
template<typename GridT>
void retraceTyped(const StrandSet& in, const GridT& grid, const TraceParams& params, double step, StrandSet& out,
                  TraceStats* stats, std::vector<StopReason>* reasonsOut, bool threaded,
                  openvdb::util::NullInterrupter* interrupter)
{
    using TreeT = typename GridT::TreeType;
    const FieldMapping map = FieldMapping::fromGrid(grid);
    const std::size_t nS = in.numStrands();
    const bool inputMode = params.vertices == RetraceVertices::Input;

    if (params.kernel == TraceKernel::Scalar) {
        // The general path of the engine, one streamline at a time (the lanes' reference).
        const BrickedField<TreeT> bricks(grid.tree());
        std::vector<StopReason> reasons;
        std::vector<std::size_t> steps;
        retraceWithSampler(in, params, step, map.worldVoxelSize(),
                           [&] { return FieldDirectionSampler<TreeT>(bricks, map, params.vanishThreshold); }, out, reasons,
                           steps, threaded, interrupter, "tracing streamlines", "retraceStrands");
        if (stats) *stats = TraceStats::count(reasons, steps);
        if (reasonsOut) *reasonsOut = std::move(reasons);
        return;
    }
    if (params.kernel == TraceKernel::LanesAvx2 && !LaneTracer<TreeT>::haveAvx2()) {
        throw UnsupportedError("retraceStrands: kernel LanesAvx2 needs a processor with AVX2");
    }

    // Input mode writes into the input's layout (compacted afterwards if a strand stops early);
    // step mode collects each strand's points. The output's storage is kept (retraceStrandsInto).
    // Elements a reused output already holds are overwritten, not zeroed again: every vertex a
    // strand keeps is written, and only new elements need mapping (growOutput()).
    std::vector<Vec3f> held = std::move(out.positions);
    out.clear();
    if (inputMode) {
        out.positions = std::move(held);
        if (out.positions.size() > in.numVertices()) out.positions.resize(in.numVertices());
        reserveHugePages(out.positions, in.numVertices());  // fresh pages 2 MiB at a time (Memory.h)
    }
    std::vector<std::uint32_t> used(inputMode ? nS : 0, 0);
    std::vector<std::vector<Vec3f>> stepPoints(inputMode ? 0 : nS);
    std::vector<StopReason> reasons(nS, StopReason::FullLength);
    std::vector<std::size_t> steps(nS, 0);
    ProgressCounter progress(interrupter, "tracing streamlines", nS, "strands");
    RetraceJob<TreeT> job{in, params, step, map, inputMode ? &out.positions : nullptr, used, stepPoints, reasons, steps, progress};

    // One task grows the output (see RetraceJob) while the bricks are built and the strands
    // traced, one LaneTracer per thread, each taking blocks of strands until none is left.
    // Whoever first needs output that is not there yet grows it, should that task not have
    // started, so nothing waits on a task that cannot run.
    const std::size_t workers = threaded ? std::size_t(std::max(1, tbb::this_task_arena::max_concurrency())) : 1;
    tbb::task_group grower;
    if (workers > 1 && inputMode) grower.run([&] { job.growOutput(); });
    try {
        const BrickedField<TreeT> bricks(grid.tree());
        if (workers > 1) {
            tbb::parallel_for(tbb::blocked_range<std::size_t>(0, workers, 1), [&](const tbb::blocked_range<std::size_t>& r) {
                for (std::size_t w = r.begin(); w != r.end(); ++w) LaneTracer<TreeT>(job, bricks).run(params.kernel);
            }, tbb::simple_partitioner());
        } else {
            LaneTracer<TreeT>(job, bricks).run(params.kernel);
        }
        job.growOutput();  // if no strand was written out (no strands)
    } catch (...) {
        job.stop = true;
        grower.wait();
        throw;
    }
    grower.wait();
    if (job.stop) throw InterruptedError("retraceStrands: interrupted");

    // Assemble.
    out.defaults = in.defaults;
    out.rootUV = in.rootUV;
    out.strandId = in.strandId;
    if (inputMode) {
        bool compact = false;
        for (std::size_t i = 0; i < nS && !compact; ++i) compact = used[i] != in.size(i);
        if (!compact) {
            out.offsets = in.offsets;
            out.thickness = in.thickness;
            out.transparency = in.transparency;
            out.color = in.color;
        } else {
            // Each strand keeps the prefix of its vertices it traced: move them down in place
            // (strand by strand in order, each destination lies at or below its source).
            out.offsets.assign(nS + 1, 0);
            for (std::size_t i = 0; i < nS; ++i) out.offsets[i + 1] = out.offsets[i] + used[i];
            const std::size_t total = out.offsets[nS];
            compactPrefixes(in, used, out.offsets, out.positions.data(), workers);
            out.positions.resize(total);
            if (!in.thickness.empty()) out.thickness.resize(total);
            if (!in.transparency.empty()) out.transparency.resize(total);
            if (!in.color.empty()) out.color.resize(total);
            tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nS, 1024), [&](const tbb::blocked_range<std::size_t>& r) {
                for (std::size_t i = r.begin(); i != r.end(); ++i) {
                    const std::size_t b = in.begin(i), o = out.offsets[i], u = used[i];
                    if (!in.thickness.empty()) std::copy_n(in.thickness.begin() + std::ptrdiff_t(b), u, out.thickness.begin() + std::ptrdiff_t(o));
                    if (!in.transparency.empty()) std::copy_n(in.transparency.begin() + std::ptrdiff_t(b), u, out.transparency.begin() + std::ptrdiff_t(o));
                    if (!in.color.empty()) std::copy_n(in.color.begin() + std::ptrdiff_t(b), u, out.color.begin() + std::ptrdiff_t(o));
                }
            });
        }
    } else {
        for (std::size_t i = 0; i < nS; ++i) out.addStrand(stepPoints[i]);
    }

    if (stats) *stats = TraceStats::count(reasons, steps);
    if (reasonsOut) *reasonsOut = std::move(reasons);
}

template<typename Fn>
void applyVec3(const openvdb::GridBase& field, const char* where, Fn&& fn)
{
    if (const auto* g = dynamic_cast<const openvdb::Vec3SGrid*>(&field)) return fn(*g);
    if (const auto* g = dynamic_cast<const openvdb::Vec3DGrid*>(&field)) return fn(*g);
    throw TypeError(std::string(where) + ": grid '" + field.getName() + "' holds " + field.valueType() +
                    " values; tracing needs a vector grid (vec3s or vec3d)");
}

} // namespace

double resolveStep(const openvdb::GridBase& field, const TraceParams& params)
{
    return resolveStepLength(params.step, FieldMapping::fromGrid(field).worldVoxelSize(), "retraceStrands");
}

StrandSet retraceStrands(const StrandSet& strands, const openvdb::GridBase& field, const TraceParams& params,
                         TraceStats* stats, std::vector<StopReason>* reasons, bool threaded,
                         openvdb::util::NullInterrupter* interrupter)
{
    StrandSet out;
    retraceStrandsInto(strands, field, params, out, stats, reasons, threaded, interrupter);
    return out;
}

void retraceStrandsInto(const StrandSet& strands, const openvdb::GridBase& field, const TraceParams& params, StrandSet& out,
                        TraceStats* stats, std::vector<StopReason>* reasons, bool threaded,
                        openvdb::util::NullInterrupter* interrupter)
{
    if (&out == &strands) {
        throw ValueError("retraceStrandsInto: the output must be another StrandSet than the input (strands are read while others are written)");
    }
    params.validate("retraceStrands");
    const double step = resolveStep(field, params);
    applyVec3(field, "retraceStrands", [&](const auto& grid) {
        retraceTyped(strands, grid, params, step, out, stats, reasons, threaded, interrupter);
    });
}

} // namespace vdbhair
