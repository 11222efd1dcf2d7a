/// @file Info.h
/// @brief `vdbhair info`, in two halves: Info.cc (registration and strand files) and InfoVdb.cc
/// (.vdb files).
#pragma once

#include "../Command.h"

#include <vdbhair/io/ReadOptions.h>
#include <vdbhair/strands/Measures.h>
#include <vdbhair/strands/StrandStats.h>

#include <functional>
#include <string>

namespace vdbhair::app {

struct InfoParams
{
    std::string input;
    std::string grid;  ///< a .vdb's points grid to summarize as strands; empty: list every grid
    bool stats = false;  ///< --stats: histograms of length, turning, curvature, vertices per strand
    StrandStatsParams statsParams;  ///< their declared parameters (strandStatsParameters()): --bins

    /// The reader's options these ask for (--grid) and @a common's (--strict among them).
    ReadOptions readOptions(const CommonOptions& common) const;
};

/// @brief Print the summary @a s of the strand file @a p.input (and the reader's warnings of
/// @a report), as prose or JSON, with the histograms of @a stats when given. @return 0
int printStrandSummary(const InfoParams& p, const StrandSummary& s, const ReadReport& report, const CommonOptions& common,
                       const StrandStatistics* stats = nullptr);

/// @brief `info` of a .vdb file: its grids, or with --grid the strands of that points grid.
int infoVdbFile(const InfoParams& p, const CommonOptions& common);

namespace info {
nlohmann::json vec3Json(const Vec3d& v);
/// @a v in six significant digits.
std::string fmt(double v);
/// @a v as (x, y, z) in fmt().
std::string fmtVec(const Vec3d& v);
} // namespace info

} // namespace vdbhair::app
