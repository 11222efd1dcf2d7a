#include "HelicoidJson.h"

#include <vdbhair/strands/Compare.h>

#include <algorithm>

namespace vdbhair {

nlohmann::json fitReport(const FitSummary& s)
{
    return {{"strands", s.strands},
            {"fitted", s.fitted},
            {"skipped", s.skipped},
            {"over_max_error", s.overMaxError},
            {"frechet_relative", {{"mean", s.meanRelative}, {"p95", s.p95Relative}}},
            {"pieces_per_strand", s.piecesPerStrand},
            {"evaluations_per_strand", s.evaluationsPerStrand},
            {"step_convergence", {{"mean", s.stepDeviationMean}, {"max", s.stepDeviationMax}, {"unconverged", s.unconverged}}},
            {"bytes", {{"fit", s.fitBytes}, {"points", s.pointBytes}}},
            {"compression", s.pointBytes / s.fitBytes}};
}

nlohmann::json growReport(const Scene& scene, const StrandSet& strands, const GrowReport& report)
{
    return {{"guides", scene.guides.size()},
            {"strands", strands.numStrands()},
            {"vertices", strands.numVertices()},
            {"guides_near_axis", report.nearAxis}};
}

nlohmann::json interpolateReport(const InterpolateResult& r, const InterpolateParams& params, const HeadObstacle& head)
{
    const bool points = params.method == InterpolationMethod::Points;
    // The new hairs made: strands, or a scene's helicoids (returnScene).
    const std::size_t count = r.strands.numStrands() > 0 ? r.strands.numStrands() : r.scene.guides.size();
    const double enteringShare = double(r.enteringHead) / double(count);
    const double guidesEnteringShare = double(r.guidesEnteringHead) / double(std::max<std::size_t>(1, r.guides));
    const nlohmann::json null(nullptr);
    return {{"method", interpolationMethodName(params.method)},
            {"blend", points ? null : nlohmann::json(helicoidBlendName(params.helicoid.blend))},
            {"grouping", points ? nlohmann::json(guideGroupingName(params.points.grouping)) : null},
            {"groups", r.groups},
            {"guides", r.guides},
            {"strands", count},
            {"vertices", params.returnScene ? null : nlohmann::json(r.strands.numVertices())},
            {"frames", frameRuleName(params.frames)},
            {"head", head.empty() ? null : nlohmann::json(head.describe(false))},
            {"roots", r.roots},
            {"roots_dropped", r.rootsDropped},
            {"cut", r.cut},
            {"clumps", r.groom.clumps},
            {"clumped", r.groom.clumped},
            {"curled", r.groom.curled},
            {"pushed_out", r.pushedOut},
            {"pushed_out_after_controls", r.groomPushedOut},
            {"vertices_too_deep", r.verticesTooDeep},
            {"entering_head", {{"strands", enteringShare}, {"guides", guidesEnteringShare}}},
            {"leaving_guide_volume",
             params.returnScene ? null
                                : nlohmann::json({{"strands", double(r.leavingVolume) / double(std::max<std::size_t>(1, r.volumeSample))},
                                                  {"sample", r.volumeSample},
                                                  {"voxel", r.volumeVoxel}})},
            {"fit_seconds", r.fitSeconds}};
}

nlohmann::json reconstructReport(const ReconstructResult& r, const ReconstructParams& params)
{
    const std::size_t S = r.helicoidErrors.relative.size();  // one error per strand
    auto frechet = [](const ReconstructErrors& e) {
        return nlohmann::json{{"mean", e.mean}, {"p95", e.p95}, {"mean_interpolated", e.meanInterpolated},
                              {"p95_interpolated", e.p95Interpolated}, {"seconds", e.seconds}};
    };
    // HairGS's oriented points and Perm's strand pairs, per way (strands/Compare.h).
    auto papers = [&params](const ReconstructErrors& e) {
        return nlohmann::json{{"oriented_points", e.oriented.empty() ? nlohmann::json(nullptr) : toJson(e.oriented, params.metersPerUnit)},
                              {"perm_position", e.permPosition}, {"perm_curvature", e.permCurvature}};
    };
    const nlohmann::json entering = r.headMeasured ? nlohmann::json({{"original", r.originalEnteringHead}, {"helicoid", r.helicoidErrors.enteringHead},
                                                                     {"points", r.pointErrors.enteringHead}, {"nearest", r.nearestErrors.enteringHead}})
                                                   : nlohmann::json(nullptr);
    return {{"strands", S},
            {"guides", r.guides.size()},
            {"unfitted", r.unfitted},
            {"guide_fraction", double(r.guides.size()) / double(S)},
            {"select", guideSelectionName(params.selection)},
            {"blend", helicoidBlendName(params.helicoid.blend)},
            {"fit", {{"mean", r.fitSummary.meanRelative}, {"p95", r.fitSummary.p95Relative},
                     {"pieces_per_strand", r.fitSummary.piecesPerStrand}, {"seconds", r.fitSeconds}}},
            {"grouping", guideGroupingName(params.points.grouping)},
            {"frechet_relative", {{"helicoid", frechet(r.helicoidErrors)}, {"points", frechet(r.pointErrors)}, {"nearest", frechet(r.nearestErrors)}}},
            {"measures", {{"helicoid", papers(r.helicoidErrors)}, {"points", papers(r.pointErrors)}, {"nearest", papers(r.nearestErrors)}}},
            {"meters_per_unit", params.metersPerUnit > 0.0 ? nlohmann::json(params.metersPerUnit) : nlohmann::json(nullptr)},
            {"leaving_guide_volume", {{"voxel", r.volumeVoxel}, {"original", r.originalLeavingVolume}, {"helicoid", r.helicoidErrors.leavingVolume},
                                      {"points", r.pointErrors.leavingVolume}, {"nearest", r.nearestErrors.leavingVolume}}},
            {"entering_head", entering}};
}

} // namespace vdbhair
