/// @file RefineOptions.h
/// @brief What `refine` and `demo` share: the refinement options and their reports
/// (defined in commands/Refine.cc and commands/Retrace.cc).
#pragma once

#include "Command.h"

#include <vdbhair/field/Refine.h>

#include <openvdb/Grid.h>

namespace vdbhair::app {

struct RefineCmdParams
{
    std::string input, output, saveField;
    double voxelSize = 0.0;
    CLI::Option* voxelOpt = nullptr;  ///< whether --voxel-size was given
    int levels = 1, iterations = 2;
    double step = 0.0;
    CLI::Option* stepOpt = nullptr;   ///< whether --step was given
    std::string integrator = "euler";
    int margin = 3;
    std::uint64_t maxVoxels = std::uint64_t(1) << 26;
    bool strict = false;
    ScalpOptions scalp;
};

void addRefineOptions(CLI::App* sub, RefineCmdParams& p);
/// @throw ValueError for out-of-range options.
RefineParams refineParamsFrom(const RefineCmdParams& p, const StrandSet& strands);
/// The field grids of @a r, each tagged `vdbhair_source` = @a source (the input file).
openvdb::GridCPtrVec fieldGrids(const RefineResult& r, const std::string& source);
nlohmann::json refineReportJson(const RefineResult& r, const RefineParams& rp);

/// The report of retrace and refine: {"strands","full_length","stopped":{...},"tangent_angle_deg":{...},"mean_displacement"}.
nlohmann::json traceReportJson(const TraceStats& s, double before, double after, double displacement);
void printTraceReport(const TraceStats& s, double before, double after, double displacement);

} // namespace vdbhair::app
