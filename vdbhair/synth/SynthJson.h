/// @file SynthJson.h
/// @brief The reports of synth, transfer and comb: what `--json` prints and what Python's
/// `return_report=True` returns, one report whichever front end ran the verb (as RefineJson.h is
/// refine's). Each verb's measures are taken once (measureSynthesis(), measureTransfer()), then
/// serialized; the text reports of the command line read the same measures.
///
/// The checks are the thresholds docs/synthesis.md and docs/editing.md give, with why each.
#pragma once

#include <vdbhair/compare/HairComparison.h>
#include <vdbhair/synth/Comb.h>
#include <vdbhair/synth/HairTransfer.h>
#include <vdbhair/synth/Synthesis.h>

#include <nlohmann/json.hpp>

#include <string>

namespace vdbhair {

/// How a synthesized hairstyle compares with its example (the report's "statistics", "checks",
/// "regions" and "compare").
struct SynthMeasures
{
    nlohmann::json stats, checks, regions;
    std::string regionText;     ///< the style by region, as text (summaryLines())
    bool measured = false;      ///< whether @c comparison was measured (the front ends' --measure)
    HairComparison comparison;
};

/// @brief The output of synthesizeHair() against @a example: distributions of length and turning,
/// wisp sizes per level, tangent coherence at the finest refinement voxel, novelty, the style by
/// region (compareStyleRegions()) and, with @a compare, what `vdbhair compare` measures. On
/// another head (@a outputMap, the map the hair was grown on) the output is measured moved back
/// onto the example's scalp, where it was made, without the head.
/// @param params the parameters the synthesis ran with (its head, up, front and output turn)
SynthMeasures measureSynthesis(const StrandSet& example, const SynthResult& r, const SynthParams& params,
                               const ScalpMap* outputMap = nullptr, bool compare = false);

/// Where a synthesis took its inputs from, as the report names them.
struct SynthSources
{
    std::string scalp;        ///< empty: the sphere fitted to the roots
    std::string region;       ///< empty: the example's region
    std::string outputScalp;  ///< empty: the example's scalp
};

/// @brief synth's report: levels, clustering, map, texture, head, stages, settings, then @a m.
nlohmann::json synthReport(const StrandSet& example, const SynthResult& r, const SynthParams& params, const ScalpMap* outputMap,
                           const SynthSources& sources, const SynthMeasures& m);

/// What transfer measures of its output (the report's figures, and the text report's).
struct TransferMeasures
{
    double spacing = 0.0;  ///< sample spacing of the turning figures, head radii
    double turnDetails = 0.0, turnBase = 0.0, turnOut = 0.0;  ///< turning per unit length
    double curlDetails = 0.0, curlBase = 0.0, curlOut = 0.0;  ///< meanCurlAmplitude(), head radii
    double curlPiece = 0.0;  ///< the pieces they are measured in (medianCurlPiece() of DETAILS), head radii
    /// clusterMeanDeviation() of the output's wisps from BASE's: mean, 90th percentile, wisps
    double deviationMean = 0.0, deviationP90 = 0.0;
    std::size_t deviationClusters = 0;
    nlohmann::json checks, regions;
    std::string regionText;
    bool measured = false;
    HairComparison comparison;
};

/// @brief The output of transferHairstyle() against DETAILS (@a details) and BASE (@a base):
/// turning compared at one sample spacing (DETAILS' median strand length over n_s - 1, in head
/// radii), the output's wisps against BASE's, BASE's regions kept and, with @a compare, what
/// `vdbhair compare` measures against BASE.
TransferMeasures measureTransfer(const StrandSet& details, const StrandSet& base, const TransferResult& tr, const TransferParams& params,
                                 bool compare = false);

/// @brief transfer's report: levels, settings, scales, turning, wisps, head, stages, then @a m.
nlohmann::json transferReport(const StrandSet& base, const TransferResult& tr, const TransferParams& params, const TransferMeasures& m);

/// @brief comb's report: wisps combed, angles to the strokes, turning, kinks, the head, stages and checks.
nlohmann::json combReport(const CombResult& r, std::size_t strokes);

} // namespace vdbhair
