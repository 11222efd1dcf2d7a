/// @file SamplerRetraceImpl.h
/// @brief Template body of SamplerRetrace.h.
#pragma once

#include <vdbhair/field/SamplerRetrace.h>  // when included on its own (it is included at that header's end)
#include <vdbhair/Exceptions.h>
#include <vdbhair/Progress.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

namespace vdbhair {

template<typename MakeSamplerT>
void retraceWithSampler(const StrandSet& in, const TraceParams& params, double step, double voxelSize,
                        const MakeSamplerT& makeSampler, StrandSet& out, std::vector<StopReason>& reasons,
                        std::vector<std::size_t>& steps, bool threaded, openvdb::util::NullInterrupter* interrupter,
                        const char* what, const std::string& where)
{
    const std::size_t nS = in.numStrands();
    const bool inputMode = params.vertices == RetraceVertices::Input;
    StreamlineRules rules;
    rules.integrator = params.integrator;
    rules.step = step;
    rules.marginLength = double(params.margin) * voxelSize;
    rules.maxSteps = params.maxSteps;
    std::vector<std::vector<Vec3f>> traced(nS);
    reasons.assign(nS, StopReason::FullLength);
    steps.assign(nS, 0);
    ProgressCounter progress(interrupter, what, nS, "strands");
    auto body = [&](std::size_t first, std::size_t last) {
        auto sampler = makeSampler();
        std::vector<double> target;
        std::vector<Vec3d> points;
        for (std::size_t i = first; i != last; ++i) {
            const std::size_t n = in.size(i);
            target.resize(n);
            double length = retraceArcLengths(in.data(i), n, target.data());
            if (!std::isfinite(length)) length = 0.0;  // vertices at infinity: not traced
            reasons[i] = traceStreamline(sampler, Vec3d(in.root(i)), length, rules, points);
            steps[i] = points.size() - 1;
            if (inputMode) writeAtArcLengths(points, length, step, reasons[i], target.data(), n, traced[i]);
            else writeSteps(points, traced[i]);
        }
    };
    // Blocks of 64 strands, each counted when done (the whole range at once would never report).
    constexpr std::size_t kBlock = 64;
    auto counted = [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t b = r.begin(); b < r.end(); b += kBlock) {
            if (progress.stopped()) return;
            const std::size_t e = std::min(r.end(), b + kBlock);
            body(b, e);
            if (progress.add(e - b)) return;
        }
    };
    if (threaded) tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nS, kBlock), counted);
    else counted(tbb::blocked_range<std::size_t>(0, nS));
    if (progress.stopped()) throw InterruptedError(where + ": interrupted");
    assembleRetrace(in, inputMode, traced, out);
}

} // namespace vdbhair
