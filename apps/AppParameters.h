/// @file AppParameters.h
/// @brief The declared parameters (vdbhair/Parameters.h) of the verbs that only the command line
/// has: `batch` (it runs processes: apps/batch/) and `demo` (refine, a preview and a report in one
/// folder). Neither has a Python function or library counterpart, so their small declarations live
/// here rather than in the library; header-only, so that tests/TestParameters.cc checks docs/cli.md
/// against them as against the library's.
#pragma once

#include <vdbhair/Parameters.h>
#include <vdbhair/field/Refine.h>

#include <string>
#include <vector>

namespace vdbhair::app {

/// How `batch` runs a JOB's inputs (the JOB, -o, --shard and --merge are its arguments).
struct BatchParams
{
    int jobs = 0;  ///< inputs at once; 0: one per core
    bool retryFailed = false;
};

inline const ParamTable<BatchParams>& batchParameters()
{
    using P = BatchParams;
    static const ParamTable<P> table = [] {
        ParamTable<P> t;
        auto jobs = makeParam<P>("jobs", "Inputs run at once; each run gets --threads cores/jobs unless args or batch's own --threads say "
                                         "otherwise; --no-clobber is passed on", "",
                                 member<P>([](P& p) -> int& { return p.jobs; }));
        jobs.min = 0;
        jobs.zeroMeans = "one per core";
        jobs.shortFlag = "-j";
        t.push_back(jobs);
        t.push_back(makeParam<P>("retry-failed", "Run only the inputs whose last record failed", "",
                                 member<P>([](P& p) -> bool& { return p.retryFailed; })));
        return t;
    }();
    return table;
}

/// refine's parameters that `demo` does not take: it always measures (its report is what an
/// artist checks the refinement by).
inline const std::vector<std::string>& demoSkippedParameters()
{
    static const std::vector<std::string> skipped{"measure"};
    return skipped;
}

/// `demo`'s parameters: refine's declaration (refineParameters()) but demoSkippedParameters().
inline const ParamTable<RefineParams>& demoParameters()
{
    static const ParamTable<RefineParams> table = [] {
        ParamTable<RefineParams> t;
        for (const Param<RefineParams>& p : refineParameters()) {
            bool skipped = false;
            for (const std::string& s : demoSkippedParameters()) skipped = skipped || s == p.name;
            if (!skipped) t.push_back(p);
        }
        return t;
    }();
    return table;
}

} // namespace vdbhair::app
