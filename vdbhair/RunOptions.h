/// @file RunOptions.h
/// @brief What every long operation takes besides its own parameters, declared once
/// (vdbhair/Parameters.h): the worker threads. The command line's `--threads` (apps/Cli.cc
/// addCommonOptions()) and every Python verb's `threads` keyword (python/src/Params.h
/// defineVerb()) are made from it.
#pragma once

#include <vdbhair/Parameters.h>

namespace vdbhair {

struct RunOptions
{
    /// Worker threads; 0: all cores. Results do not depend on it.
    int threads = 0;
};

/// @brief The run options declared once: threads.
inline const ParamTable<RunOptions>& runParameters()
{
    using P = RunOptions;
    static const ParamTable<P> table = [] {
        ParamTable<P> t;
        auto threads = makeParam<P>("threads", "Worker threads; results do not depend on it", "", member<P>([](P& p) -> int& { return p.threads; }));
        threads.min = 0;
        threads.zeroMeans = "all cores";
        t.push_back(threads);
        return t;
    }();
    return table;
}

} // namespace vdbhair
