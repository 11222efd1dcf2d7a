#include "SynthJson.h"

#include <vdbhair/Quantile.h>
#include <vdbhair/field/TangentField.h>
#include <vdbhair/strands/Measures.h>
#include <vdbhair/synth/StyleRegions.h>
#include <vdbhair/synth/SynthesisReport.h>

#include <algorithm>
#include <cmath>

namespace vdbhair {

namespace {

double meanOf(const std::vector<double>& v)
{
    double s = 0.0;
    for (double x : v) s += x;
    return v.empty() ? 0.0 : s / double(v.size());
}

/// Output wisp sizes against the example's, per level.
nlohmann::json wispSizes(const SynthResult& r)
{
    nlohmann::json wisps = nlohmann::json::array();
    for (std::size_t l = 0; l < r.clusterOf.size(); ++l) {
        // Example: sizes in strands of the level-(l+1) clusters (labels composed down to the strands).
        std::vector<std::int32_t> ex(r.example.levels[0].count());
        for (std::size_t s = 0; s < ex.size(); ++s) {
            std::uint32_t c = std::uint32_t(s);
            for (std::size_t k = 0; k <= l; ++k) c = r.example.clusterings[k].label[c];
            ex[s] = std::int32_t(c);
        }
        const std::vector<double> a = clusterSizes(ex), b = clusterSizes(r.clusterOf[l]);
        wisps.push_back({{"level", l + 1}, {"example_clusters", a.size()}, {"output_clusters", b.size()},
                         {"example_mean_size", meanOf(a)}, {"output_mean_size", meanOf(b)},
                         {"size_distance", relativeWasserstein(a, b)}});
    }
    return wisps;
}

/// Distributions, wisps, coherence and novelty of @a output against @a example, and the checks.
nlohmann::json synthStatistics(const StrandSet& example, const SynthResult& r, const StrandSet& output, double voxelSize,
                               nlohmann::json& checks)
{
    nlohmann::json j;
    // Per-strand measures: distances between distributions (relative 1-Wasserstein).
    std::vector<double> le, lo;
    for (float x : strandLengths(example)) le.push_back(x);
    for (float x : strandLengths(output)) lo.push_back(x);
    j["length_distance"] = relativeWasserstein(le, lo);
    j["turning_distance"] = relativeWasserstein(turningPerLength(example), turningPerLength(output));
    j["wisps"] = wispSizes(r);
    // Tangent coherence of both at the finest refinement voxel.
    FieldParams fp;
    fp.voxelSize = voxelSize;
    const double ce = meanCoherence(estimateTangentField(example, fp)), co = meanCoherence(estimateTangentField(output, fp));
    j["coherence"] = {{"example", ce}, {"output", co}, {"voxel_size", voxelSize}};
    const NoveltyStats nov = measureNovelty(example, output, r.map->radius());
    j["novelty"] = {{"output_to_example_median", nov.outputMedian}, {"example_to_example_median", nov.exampleMedian},
                    {"copies", nov.copies}};
    // The thresholds (docs/synthesis.md says why each).
    checks = {{"length", j["length_distance"].get<double>() <= 0.15},
              {"turning", j["turning_distance"].get<double>() <= 0.25},
              {"coherence", co >= ce - 0.03},
              {"new", nov.copies <= 0.01 && nov.outputMedian >= 0.5 * nov.exampleMedian}};
    return j;
}

nlohmann::json stagesJson(const std::vector<SynthStage>& stages)
{
    nlohmann::json j = nlohmann::json::object();
    for (const SynthStage& s : stages) j[s.name] = s.seconds;
    return j;
}

double share(std::size_t part, std::size_t whole)
{
    return double(part) / double(std::max<std::size_t>(1, whole));
}

} // namespace

SynthMeasures measureSynthesis(const StrandSet& example, const SynthResult& r, const SynthParams& params, const ScalpMap* outputMap,
                               bool compare)
{
    SynthMeasures m;
    const double finestVoxel = r.refineVoxelSizes.front();
    // On another head the output is measured where it was made, on the example's scalp (moved
    // back: the same (u, v), height and local offsets), so that its figures compare with the example's.
    StrandSet movedBack;
    if (outputMap) movedBack = moveToScalp(r.strands, *outputMap, *r.map, -params.outputTurn);
    const StrandSet& output = outputMap ? movedBack : r.strands;
    m.stats = synthStatistics(example, r, output, finestVoxel, m.checks);
    // The style region by region, output beside example, in the example's head frame (on another
    // head, the output moved back; the head then is not the example's, so no inside-head figure).
    const ScalpSphere& sphere = r.map->sphere();
    m.regions = compareStyleRegions(example, output, sphere.center, sphere.up, sphere.radius,
                                    outputMap || r.head == "none" ? nullptr : &params.head, &m.regionText, params.front);
    if (compare) {
        m.comparison = measureAgainst(example, output, outputMap ? nullptr : &params.head, /*corresponding=*/false);
        m.measured = true;
    }
    return m;
}

nlohmann::json synthReport(const StrandSet& example, const SynthResult& r, const SynthParams& params, const ScalpMap* outputMap,
                           const SynthSources& sources, const SynthMeasures& m)
{
    nlohmann::json levels = nlohmann::json::array();
    for (std::size_t l = 0; l < r.output.size(); ++l)
        levels.push_back({{"level", l}, {"example", r.example.levels[l].count()}, {"output", r.output[l].count()},
                          {"refine_corrected", r.refinedCorrected[l]}, {"refine_voxel_size", r.refineVoxelSizes[l]}});
    nlohmann::json energy = nlohmann::json::array();
    for (const Clustering& c : r.example.clusterings)
        energy.push_back({{"energy", c.energy}, {"clusters", c.clusters}, {"largest_distance", c.largestDistance}});
    double explained = 1.0;
    if (r.pca.totalVariance > 0) {
        double s = 0;
        for (double v : r.pca.variance) s += v;
        explained = s / r.pca.totalVariance;
    }
    return {{"strands", r.strands.numStrands()}, {"vertices", r.strands.numVertices()}, {"levels", levels}, {"clustering", energy},
            {"map", {{"width", r.grid.width}, {"height", r.grid.height}, {"components", r.pca.components}, {"explained_variance", explained}}},
            {"texture", {{"energy", r.texture.energy}, {"iterations", r.texture.iterations}}},
            {"head_radius", r.map->radius()}, {"up", {r.up.x(), r.up.y(), r.up.z()}},
            {"region", sources.region.empty() ? "the example's" : sources.region}, {"output_area", r.outputArea},
            {"output_scalp", sources.outputScalp.empty() ? "the example's" : sources.outputScalp},
            {"output_head_radius", outputMap ? outputMap->radius() : r.map->radius()},
            {"scalp", sources.scalp.empty() ? "sphere fitted to the roots" : sources.scalp}, {"layout", synthLayoutName(params.layout)},
            {"detail", detailBlendName(params.detailBlend)}, {"detail_scale", detailScaleName(params.detailScale)},
            {"match", {{"balance", params.match.balance}, {"candidates", params.match.candidates}, {"place", params.match.place}}},
            {"head", {{"head", r.head}, {"pushed_out", r.headPushedOut},
                      {"entering", {{"output", share(r.enteringHead, r.strands.numStrands())},
                                    {"example", outputMap ? nlohmann::json(nullptr) : nlohmann::json(share(r.exampleEnteringHead, example.numStrands()))}}}}},
            {"stages", stagesJson(r.stages)}, {"statistics", m.stats}, {"checks", m.checks}, {"regions", m.regions},
            {"compare", m.measured ? toJson(m.comparison) : nlohmann::json(nullptr)}};
}

TransferMeasures measureTransfer(const StrandSet& details, const StrandSet& base, const TransferResult& tr, const TransferParams& params,
                                 bool compare)
{
    TransferMeasures m;
    const SynthResult& r = tr.result;
    const int ns = params.synth.vertices;
    // Turning compared at one sample spacing in head radii, DETAILS' own: its median strand
    // length over n_s - 1 (a fixed vertex count would undersample the longer hairstyle's curls).
    m.spacing = double(upperMedian(strandLengths(details))) / tr.detailsMap->radius() / double(ns - 1);
    m.turnDetails = meanTurningPerLengthAtSpacing(details, m.spacing * tr.detailsMap->radius());
    m.turnBase = meanTurningPerLengthAtSpacing(base, m.spacing * r.map->radius());
    m.turnOut = meanTurningPerLengthAtSpacing(r.strands, m.spacing * r.map->radius());
    const std::vector<double> dev = clusterMeanDeviation(r.strands, r.clusterOf.back(), base, tr.baseLabel, ns, params.smoothing);
    m.deviationMean = meanOf(dev);
    m.deviationP90 = quantile(dev, 0.9);
    m.deviationClusters = dev.size();
    // Turning per head radius: each hairstyle in units of its own head (detail arrives scaled so).
    const double rd = tr.detailsMap->radius(), rb = r.map->radius();
    // Curl amplitude in pieces of DETAILS' median strand length, each in its own head's radii.
    m.curlPiece = medianCurlPiece(details, rd);
    m.curlDetails = meanCurlAmplitude(details, rd, m.curlPiece);
    m.curlBase = meanCurlAmplitude(base, rb, m.curlPiece);
    m.curlOut = meanCurlAmplitude(r.strands, rb, m.curlPiece);
    m.checks = {{"detail", std::abs(m.turnOut * rb - m.turnDetails * rd) <= 0.1 * m.turnDetails * rd},
                {"curl", std::abs(m.curlOut - m.curlDetails) <= 0.1 * m.curlDetails},
                {"coarse_shape", m.deviationMean <= 0.1}};
    // BASE's regions kept: the output against BASE, region by region, in BASE's head frame.
    const ScalpSphere& sphere = r.map->sphere();
    m.regions = compareStyleRegions(base, r.strands, sphere.center, sphere.up, sphere.radius, r.head == "none" ? nullptr : &params.synth.head,
                                    &m.regionText, params.synth.front);
    if (compare) {
        m.comparison = measureAgainst(base, r.strands);
        m.measured = true;
    }
    return m;
}

nlohmann::json transferReport(const StrandSet& base, const TransferResult& tr, const TransferParams& params, const TransferMeasures& m)
{
    const SynthResult& r = tr.result;
    const double rd = tr.detailsMap->radius(), rb = r.map->radius();
    nlohmann::json levels = nlohmann::json::array();
    for (std::size_t l = 0; l < r.output.size(); ++l)
        levels.push_back({{"level", l}, {"details", r.example.levels[l].count()}, {"output", r.output[l].count()},
                          {"refine_corrected", r.refinedCorrected[l]}});
    return {{"strands", r.strands.numStrands()}, {"vertices", r.strands.numVertices()}, {"levels", levels}, {"guides", params.guides},
            {"smoothing", params.smoothing}, {"smooth_base", params.smoothBase}, {"detail", detailBlendName(params.synth.detailBlend)},
            {"detail_laid_by", detailScaleName(params.synth.detailScale)},
            {"match", {{"balance", params.synth.match.balance}, {"candidates", params.synth.match.candidates}, {"place", params.synth.match.place}}},
            {"head_radius", {{"details", rd}, {"base", rb}}},
            {"detail_scale", tr.detailScale}, {"length_ratio", tr.lengthRatio},
            {"turning_per_length", {{"details", m.turnDetails}, {"base", m.turnBase}, {"output", m.turnOut}, {"spacing_head_radii", m.spacing}}},
            {"output_vertices", tr.outputVertices}, {"details_smoothing", tr.detailsSmoothing},
            {"turning_per_head_radius", {{"details", m.turnDetails * rd}, {"base", m.turnBase * rb}, {"output", m.turnOut * rb}}},
            {"curl_amplitude", {{"details", m.curlDetails}, {"base", m.curlBase}, {"output", m.curlOut}, {"piece_head_radii", m.curlPiece}}},
            {"coarse_deviation", {{"mean", m.deviationMean}, {"p90", m.deviationP90}, {"clusters", m.deviationClusters}}},
            {"head", {{"head", r.head}, {"pushed_out", r.headPushedOut},
                      {"entering", {{"output", share(r.enteringHead, r.strands.numStrands())},
                                    {"base", double(r.exampleEnteringHead) / double(base.numStrands())}}}}},
            {"stages", stagesJson(r.stages)}, {"checks", m.checks}, {"regions", m.regions},
            {"compare", m.measured ? toJson(m.comparison) : nlohmann::json(nullptr)}};
}

nlohmann::json combReport(const CombResult& r, std::size_t strokes)
{
    const CombStats& s = r.stats;
    // Checks (docs/editing.md): tangents in reach turned toward the strokes, curl kept within
    // 10 % on the moved strands, no vertex pushed deeper into the head, no new kink.
    const nlohmann::json checks = {
        {"turned", s.reachVertices == 0 || s.angleAfter < s.angleBefore},
        {"curl_kept", s.movedStrands == 0 || std::abs(s.turningAfter - s.turningBefore) <= 0.1 * s.turningBefore},
        {"kept_out_of_head", s.insideHeadAfter <= s.insideHeadBefore},
        {"no_new_kinks", s.newKinks == 0}};
    return {{"strokes", strokes}, {"strands", r.strands.numStrands()},
            {"clusters", s.clusters}, {"combed_clusters", s.combedClusters}, {"moved_strands", s.movedStrands},
            {"angle_to_stroke_deg", {{"before", s.angleBefore}, {"after", s.angleAfter}, {"vertices", s.reachVertices}}},
            {"turning_per_length", {{"before", s.turningBefore}, {"after", s.turningAfter}}},
            {"new_kinks", {{"strands", s.newKinks}, {"degrees", kKinkDegrees}, {"combed_less", s.backedOff}}},
            {"head", {{"head", s.head}, {"deflected_strands", s.headDeflected},
                      {"inside_vertices", {{"before", s.insideHeadBefore}, {"after", s.insideHeadAfter}}}}},
            {"stages", stagesJson(r.stages)}, {"checks", checks}};
}

} // namespace vdbhair
