/// @file Parallel.h
/// @brief The library's one serial-or-threaded loop over indices. Each index is done by exactly one
/// call of the body, so a body that writes only its own index's results gives the same output on
/// any thread count (the library's rule: results do not depend on it).
#pragma once

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cstddef>

namespace vdbhair {

/// @brief @a body(i) for every i in [0, @a count): on TBB's threads in chunks of at least @a grain
/// indices when @a threaded, else in order on the calling thread.
template <typename Body>
void forEachIndex(std::size_t count, bool threaded, Body&& body, std::size_t grain = 64)
{
    if (threaded) {
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, count, grain), [&](const tbb::blocked_range<std::size_t>& r) {
            for (std::size_t i = r.begin(); i != r.end(); ++i) body(i);
        });
    } else {
        for (std::size_t i = 0; i < count; ++i) body(i);
    }
}

/// @brief @a body(range) over [0, @a count): on TBB's threads in ranges of at least @a grain
/// indices when @a threaded, else one range in order (for bodies with per-range scratch space).
template <typename Body>
void forEachRange(std::size_t count, bool threaded, std::size_t grain, Body&& body)
{
    if (threaded) tbb::parallel_for(tbb::blocked_range<std::size_t>(0, count, grain), body);
    else body(tbb::blocked_range<std::size_t>(0, count));
}

} // namespace vdbhair
