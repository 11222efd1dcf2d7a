/// @file RefineJson.h
/// @brief The report of a refinement (refineStrands()) as the JSON that `refine --json` prints and
/// Python's `refine(..., return_report=True)` returns: one report, whichever front end ran it.
#pragma once

#include <vdbhair/field/Refine.h>
#include <vdbhair/field/RefineReport.h>

#include <nlohmann/json.hpp>

namespace vdbhair {

/// @brief What an artist sees of a refinement (RefineMeasures) as JSON.
nlohmann::json toJson(const RefineMeasures& m);

/// @brief The settings, then the finest level's measures (with RefineParams::measure), then
/// `per_level`: each level's voxel size, what the consistent retrace corrected or where the field
/// retrace stopped, and its measures.
nlohmann::json refineReport(const RefineResult& r, const RefineParams& rp);

} // namespace vdbhair
