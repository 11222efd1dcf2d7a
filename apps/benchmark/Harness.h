/// @file Harness.h
/// @brief The benchmark's machinery, shared by its sections (Sections.h): wall-clock timing, peak
/// memory, child processes measured from the outside, and the synthetic hairstyle several sections
/// start from.
#pragma once

#include <vdbhair/strands/StrandSet.h>

#include <algorithm>
#include <cstddef>
#include <string>
#include <vector>

namespace vdbhair::bench {

/// Seconds on a steady clock (for differences).
double now();

/// This process's peak resident memory so far, MiB (getrusage).
double peakMiB();

/// Best of @a reps runs of @a fn (seconds).
template<typename Fn>
double timeBest(int reps, Fn&& fn)
{
    double best = 1e30;
    for (int r = 0; r < reps; ++r) {
        const double t0 = now();
        fn();
        best = std::min(best, now() - t0);
    }
    return best;
}

/// @a count strands of @a vertices vertices: copies of @a base (resampled), each strand moved by a
/// seeded random offset (deterministic: seeded by the copy and strand index).
StrandSet jitteredCopies(const StrandSet& base, std::size_t count, std::size_t vertices, float jitter);

/// One finished child process: wall seconds, CPU seconds (user + system), peak resident MiB.
struct ProcessRun
{
    double wall = 0.0, cpu = 0.0, peakMiB = 0.0;
    int status = 0;
};

/// @brief Run @a args (a program and its arguments) as a process with stdout and stderr sent to
/// /dev/null (stdout to @a stdoutPath if given), and measure it from the outside (wait4's rusage:
/// the child's own CPU and peak RSS).
ProcessRun runProcess(const std::vector<std::string>& args, const std::string& stdoutPath = std::string());

} // namespace vdbhair::bench
