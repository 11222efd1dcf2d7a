/// @file HelicoidJson.h
/// @brief The reports of fit, grow, interpolate and reconstruct: what `--json` prints and what
/// Python's report returns, one report whichever front end ran the verb (as SynthJson.h is
/// synth's). The front ends add only what is theirs: the command line its file names, its clock
/// ("seconds") and the rates made from it; Python its arrays.
#pragma once

#include <vdbhair/helicoid/GuideInterpolation.h>
#include <vdbhair/helicoid/HelicoidFit.h>
#include <vdbhair/helicoid/Reconstruction.h>
#include <vdbhair/helicoid/Scene.h>

#include <nlohmann/json.hpp>

namespace vdbhair {

/// @brief fit's report (summarizeFits()): strands fitted and skipped, the discrete Fréchet
/// distance relative to length (mean, 95th percentile) and how many exceed the tolerance, pieces
/// and evaluations per strand, step convergence, and the bytes of fits against points.
nlohmann::json fitReport(const FitSummary& s);

/// @brief grow's report: guides, strands and vertices grown (growScene()), and the guides that
/// pass near a piece's singular axis (@a report).
nlohmann::json growReport(const Scene& scene, const StrandSet& strands, const GrowReport& report);

/// @brief interpolate's report (interpolateGuides()): method and settings, guides, new hairs and
/// their vertices, roots left bare and hairs cut, the groom controls, the head (@a head, what the
/// new hair was kept out of; empty: none) and the shares passing into it and leaving the guides'
/// volume, and the time fitting strand guides took (`fit_seconds`). The interpolation's own time
/// (InterpolateResult::seconds) is the front ends' to add.
nlohmann::json interpolateReport(const InterpolateResult& r, const InterpolateParams& params, const HeadObstacle& head);

/// @brief reconstruct's report (reconstructHairstyle()): strands and guides, the selection and both
/// interpolations' settings, the guides' fits, each way's (helicoid, points, nearest guide)
/// discrete Fréchet distance relative to length and the papers' measures, and the shares leaving
/// the guides' volume and (with a head) passing into it, beside the original's.
nlohmann::json reconstructReport(const ReconstructResult& r, const ReconstructParams& params);

} // namespace vdbhair
