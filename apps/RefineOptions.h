/// @file RefineOptions.h
/// @brief What `refine` and `demo` share: the refinement options and the prose report (the JSON
/// report is the library's, RefineJson.h)
/// (defined in commands/Refine.cc; the trace report in commands/Retrace.cc).
#pragma once

#include "Command.h"
#include "HeadOptions.h"

#include <vdbhair/field/Refine.h>
#include <vdbhair/field/RefineJson.h>
#include <vdbhair/field/TangentAngles.h>

#include <openvdb/Grid.h>

#include <optional>

namespace vdbhair::app {

/// The command line of refine: options bind to the library's RefineParams fields, so `--help`
/// shows the library's defaults.
struct RefineCmdParams
{
    std::string input, output, saveField;
    RefineParams refine;  ///< its declared parameters (refineParameters()) are options
    HeadOptions head;
    ScalpOptions scalp;
};

/// @brief refine's declared parameters but those in @a skip, --head and --scalp.
void addRefineOptions(CLI::App* sub, RefineCmdParams& p, const std::vector<std::string>& skip = {});
/// @throw ValueError for out-of-range options, IoError/FormatError for an unreadable --head.
RefineParams refineParamsFrom(const RefineCmdParams& p, const StrandSet& strands, const CommonOptions& common);
/// The field grids of @a r, each tagged `vdbhair_source` = @a source (the input file).
openvdb::GridCPtrVec fieldGrids(const RefineResult& r, const std::string& source);
void printRefineReport(const RefineResult& r, const RefineParams& rp);

/// retrace's text report (its JSON is the library's retraceReport(), vdbhair/field/FieldJson.h).
void printTraceReport(const TraceStats& s, const std::optional<TangentAngles>& angles, double displacement);

} // namespace vdbhair::app
