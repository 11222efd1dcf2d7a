// vdbhair.synth, transfer and comb: Wang et al.'s synthesis, detail transfer and combing.
#include "Common.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/compare/HairComparison.h>
#include <vdbhair/field/Refine.h>
#include <vdbhair/io/MeshFile.h>
#include <vdbhair/scalp/ScalpSurface.h>
#include <vdbhair/synth/Comb.h>
#include <vdbhair/synth/HairTransfer.h>
#include <vdbhair/synth/StyleRegions.h>
#include <vdbhair/synth/Synthesis.h>

#include <nlohmann/json.hpp>

#include <pybind11/stl.h>

#include <cmath>
#include <memory>
#include <optional>
#include <tuple>

namespace vdbhair::py {

namespace {


/// The hierarchy's keywords (as the commands' addSynthHierarchyOptions()), shared by synth,
/// transfer and comb.
void setHierarchy(SynthParams& p, int levels, std::uint64_t seed, int vertices, double threshold, int initialClusters,
                  const std::optional<std::array<double, 3>>& up)
{
    p.cluster.levels = levels;
    p.seed = seed;
    p.vertices = vertices;
    p.cluster.threshold = threshold;
    p.cluster.initialClusters = initialClusters;
    if (up) p.up = Vec3d((*up)[0], (*up)[1], (*up)[2]);
}

} // namespace

void bindSynthesis(pyb::module_& m)
{
    const SynthParams synthDefaults;
    m.def(
        "synth",
        [](const StrandsPtr& example, int levels, std::optional<std::size_t> strands, std::uint64_t seed, int vertices,
           double threshold, int initialClusters, int components, double mapSpacing, const std::string& layout,
           const std::string& detail, const std::string& detailScale, double matchBalance, int matchCandidates, double matchPlace, double placeWeight,
           double nearby, const std::string& rootDensity, bool refine, std::optional<std::string> refineMode,
           double voxelSize, std::optional<std::array<double, 3>> up, std::optional<std::array<double, 3>> front, std::optional<PathArg> scalp,
           std::optional<pyb::array_t<double, pyb::array::c_style | pyb::array::forcecast>> region,
           std::optional<PathArg> outputScalp, double outputTurn, bool measure, bool returnReport, int threads,
           const pyb::object& progress) -> pyb::object {
            SynthParams p;
            std::vector<Vec3d> regionPoints;
            if (region) {
                if (region->ndim() != 2 || region->shape(1) != 3) throw ValueError("synth: region must be an (N, 3) array of points");
                const auto r = region->unchecked<2>();
                regionPoints.reserve(std::size_t(r.shape(0)));
                for (pyb::ssize_t i = 0; i < r.shape(0); ++i) regionPoints.emplace_back(r(i, 0), r(i, 1), r(i, 2));
            }
            setHierarchy(p, levels, seed, vertices, threshold, initialClusters, up);
            if (front) p.front = Vec3d((*front)[0], (*front)[1], (*front)[2]);
            p.components = components;
            p.mapSpacing = mapSpacing;
            p.layout = synthLayoutFromName(layout);
            p.detailBlend = detailBlendFromName(detail);
            p.detailScale = detailScaleFromName(detailScale);
            p.match.balance = matchBalance;
            p.match.candidates = matchCandidates;
            p.match.place = matchPlace;
            p.placeWeight = placeWeight;
            if (rootDensity != "example" && rootDensity != "even") throw ValueError("synth: root_density '" + rootDensity + "': must be example or even");
            p.exampleDensity = rootDensity == "example";
            p.texture.nearbyRadius = nearby;
            p.refine = refine;
            if (refineMode) p.refineMode = refineModeFromName(*refineMode);
            p.voxelSize = voxelSize;
            if (strands) {
                if (*strands == 0) throw ValueError("synth: strands=0: must be at least 1");
                if (example->empty()) throw ValueError("synth: the example has no strands");
                p.strands = *strands;
            }
            p.validate("synth");
            if (!std::isfinite(outputTurn)) throw ValueError("synth: output_turn must be a finite angle in degrees");
            if (outputTurn != 0.0 && !outputScalp) throw ValueError("synth: output_turn needs output_scalp");
            p.outputTurn = outputTurn * M_PI / 180.0;
            if (outputScalp && !region) throw ValueError("synth: output_scalp needs region=, the points where the hair grows on that head");
            std::shared_ptr<const ScalpMap> other;
            SynthResult r = runLong(threads, progress, [&](WorkInterrupter* interrupter) {
                openvdb::FloatGrid::Ptr grid = scalp ? readScalp(*scalp, interrupter) : nullptr;
                if (outputScalp) {
                    std::vector<Vec3f> pts(regionPoints.begin(), regionPoints.end());
                    const openvdb::FloatGrid::Ptr otherGrid = readScalp(*outputScalp, interrupter);
                    other = scalpMapOfPoints(pts, p.up, otherGrid);
                    p.head = HeadObstacle::levelSet(otherGrid);  // the head the hair grows on (as the command)
                }
                return synthesizeHair(*example, p, grid, true, interrupter, region ? &regionPoints : nullptr, other);
            });
            pyb::object comparison = pyb::none();  // as synth --measure --json's "compare"
            if (measure && returnReport) {
                const HairComparison c = runLong(threads, pyb::none(), [&](WorkInterrupter*) {
                    return other ? measureAgainst(*example, moveToScalp(r.strands, *other, *r.map, -p.outputTurn), nullptr, false)
                                 : measureAgainst(*example, r.strands, &p.head, false);
                });
                comparison = toPython(toJson(c));
            }
            pyb::object regions = pyb::none();  // as synth --json's "regions"
            if (returnReport) {
                const ScalpSphere& sphere = r.map->sphere();
                regions = toPython(runLong(threads, pyb::none(), [&](WorkInterrupter*) {
                    return other ? compareStyleRegions(*example, moveToScalp(r.strands, *other, *r.map, -p.outputTurn), sphere.center, sphere.up,
                                                       sphere.radius, nullptr, nullptr, p.front)
                                 : compareStyleRegions(*example, r.strands, sphere.center, sphere.up, sphere.radius, r.head == "none" ? nullptr : &p.head,
                                                       nullptr, p.front);
                }));
            }
            auto out = std::make_shared<StrandSet>(std::move(r.strands));
            if (!returnReport) return pyb::cast(out);
            pyb::dict report;
            report["compare"] = comparison;
            report["regions"] = regions;
            pyb::list levelsList, stages, clusters;
            for (std::size_t l = 0; l < r.output.size(); ++l) {
                pyb::dict d;
                d["example"] = r.example.levels[l].count();
                d["output"] = r.output[l].count();
                d["refine_voxel_size"] = r.refineVoxelSizes[l];
                levelsList.append(d);
            }
            for (const SynthStage& s : r.stages) stages.append(pyb::make_tuple(s.name, s.seconds));
            for (const std::vector<std::int32_t>& c : r.clusterOf)
                clusters.append(pyb::array_t<std::int32_t>(pyb::ssize_t(c.size()), c.data()));
            report["levels"] = levelsList;
            report["stages"] = stages;
            report["cluster_of"] = clusters;
            report["head_radius"] = r.map->radius();
            report["up"] = pyb::make_tuple(r.up.x(), r.up.y(), r.up.z());
            report["output_area"] = r.outputArea;
            report["head"] = pyb::dict(pyb::arg("head") = r.head, pyb::arg("pushed_out") = r.headPushedOut, pyb::arg("entering_output") = r.enteringHead,
                                       pyb::arg("entering_example") = r.exampleEnteringHead);
            return pyb::make_tuple(out, report);
        },
        pyb::arg("example"), pyb::kw_only(), pyb::arg("levels") = synthDefaults.cluster.levels, pyb::arg("strands") = pyb::none(),
        pyb::arg("seed") = synthDefaults.seed, pyb::arg("vertices") = synthDefaults.vertices,
        pyb::arg("threshold") = synthDefaults.cluster.threshold, pyb::arg("initial_clusters") = synthDefaults.cluster.initialClusters,
        pyb::arg("components") = synthDefaults.components, pyb::arg("map_spacing") = synthDefaults.mapSpacing,
        pyb::arg("layout") = synthLayoutName(synthDefaults.layout), pyb::arg("detail") = detailBlendName(synthDefaults.detailBlend),
        pyb::arg("detail_scale") = detailScaleName(synthDefaults.detailScale), pyb::arg("match_balance") = synthDefaults.match.balance,
        pyb::arg("match_candidates") = synthDefaults.match.candidates, pyb::arg("match_place") = synthDefaults.match.place,
        pyb::arg("place_weight") = synthDefaults.placeWeight, pyb::arg("nearby") = synthDefaults.texture.nearbyRadius,
        pyb::arg("root_density") = synthDefaults.exampleDensity ? "example" : "even", pyb::arg("refine") = synthDefaults.refine,
        pyb::arg("refine_mode") = pyb::none(), pyb::arg("voxel_size") = synthDefaults.voxelSize, pyb::arg("up") = pyb::none(), pyb::arg("front") = pyb::none(),
        pyb::arg("scalp") = pyb::none(), pyb::arg("region") = pyb::none(), pyb::arg("output_scalp") = pyb::none(),
        pyb::arg("output_turn") = 0.0, pyb::arg("measure") = false, pyb::arg("return_report") = false, pyb::arg("threads") = 0,
        pyb::arg("progress") = pyb::none(),
        R"doc(A new hairstyle in the style of an example (Wang et al. 2009, §3-5): ``vdbhair synth``.

Hierarchical clustering, PCA feature maps and texture optimization, cluster-oriented detail
transfer and vector-field refinement per level; deterministic for a seed, the same for any
thread count. docs/synthesis.md, explains every option and its measured default.

Args:
    example: Strands (many: at least 4^(levels-1)).
    levels: levels of the hierarchy, the strands included (2 to 5).
    strands: strands in the output (None: the example's density over the region).
    seed: random seed.
    vertices: vertices per strand, n_s.
    threshold: adaptive clustering threshold epsilon (L2 over n_s vertices, head radii squared).
    initial_clusters: k0 of adaptive clustering.
    components: PCA components of the feature maps, n_f.
    map_spacing: feature-map pixel spacing in scalp (u, v) radians.
    layout: "synthesize" (texture optimization) or "example" (the example's own map).
    detail: "edges" (each strand's own edges re-laid along the output centre), "root-frame" or "paper" (Eq. 7).
    detail_scale: "strand" (each strand at its own length and pitch), "index" (vertex by vertex) or "arc-length".
    match_balance: each example wisp serves at most this times its own share of the output (its part of the example's strands), each of its strands at most this times its even share of an output wisp (0: nearest wisp and strand).
    match_candidates: example wisps considered per output wisp in balanced matching.
    match_place: how much an output wisp prefers example wisps near its own place, against their shape (0: by shape alone).
    place_weight: texture synthesis place guidance (0: none).
    nearby: reach of place guidance and initial patch offsets, a fraction of the map.
    root_density: "example" (new roots at the example's density, place by place) or "even" (evenly over the region).
    refine: refine every level (Wang et al. §5.3).
    refine_mode: None (refine's default, "consistent") or "field".
    voxel_size: refinement voxel of the finest level, world units (0: refine's suggestion).
    up: the scalp's up axis (None: the roots' mean direction from the head's centre).
    front: the head's front for the report's "regions" (None: where the example's hairline is highest).
    scalp: a path to a scalp: .vdb with a level set 'surface', or a head mesh (.ply, .obj).
    region: where the new hair grows, an (N, 3) array of points on the scalp (roots() positions,
        another hairstyle's roots); None: the example's region. The count scales with the area.
    output_scalp: a path to another head (scalp .vdb or mesh) that region= lies on: the hairstyle
        is made at the region's (u, v) and moved onto it through scalp space.
    output_turn: degrees about the up axis the layout turns on output_scalp (heads facing different ways).
    measure: with return_report, the report's "compare" holds the output against the example, as
        ``vdbhair.compare(example, output)`` (on output_scalp, the output moved back onto the example's scalp).
    return_report: also return a dict (levels, stages with seconds, cluster_of arrays per level, head radius, up, output_area,
        head: the head new hair is kept out of, the strands pushed out, the output's and the example's strands passing into it,
        regions: the style region by region, output beside example, as synth --json's "regions", StyleRegions.h).
    threads: worker threads, 0 for all cores.
    progress: optional callable ``progress(stage, done, total, unit)``.

Returns:
    Strands, or (Strands, report) with return_report.)doc");

    const TransferParams transferDefaults;
    m.def(
        "transfer",
        [](const StrandsPtr& details, const StrandsPtr& base, bool guides, std::optional<std::size_t> strands, double smoothing,
           bool smoothBase, int levels, std::uint64_t seed, int vertices, double threshold, int initialClusters, int components,
           const std::string& detail, const std::string& detailScale, double matchBalance, int matchCandidates, double matchPlace, bool refine,
           std::optional<std::string> refineMode,
           double voxelSize, std::optional<std::array<double, 3>> up, std::optional<std::array<double, 3>> front, std::optional<PathArg> scalp,
           bool measure, bool returnReport, int threads, const pyb::object& progress) -> pyb::object {
            TransferParams p;
            p.guides = guides;
            if (strands) {
                if (*strands == 0) throw ValueError("transfer: strands=0: must be at least 1");
                if (!guides) throw ValueError("transfer: strands: the output has the base's strands; strands needs guides=True");
                p.strands = *strands;
            }
            p.smoothing = smoothing;
            p.smoothBase = smoothBase;
            SynthParams& s = p.synth;
            setHierarchy(s, levels, seed, vertices, threshold, initialClusters, up);
            if (front) s.front = Vec3d((*front)[0], (*front)[1], (*front)[2]);
            s.components = components;
            s.detailBlend = detailBlendFromName(detail);
            s.detailScale = detailScaleFromName(detailScale);
            s.match.balance = matchBalance;
            s.match.candidates = matchCandidates;
            s.match.place = matchPlace;
            s.refine = refine;
            if (refineMode) s.refineMode = refineModeFromName(*refineMode);
            s.voxelSize = voxelSize;
            p.validate("transfer");
            TransferResult r = runLong(threads, progress, [&](WorkInterrupter* interrupter) {
                openvdb::FloatGrid::Ptr grid = scalp ? readScalp(*scalp, interrupter) : nullptr;
                return transferHairstyle(*details, *base, p, grid, true, interrupter);
            });
            pyb::object comparison = pyb::none();  // as transfer --measure --json's "compare"
            if (measure && returnReport)
                comparison = toPython(toJson(runLong(threads, pyb::none(), [&](WorkInterrupter*) { return measureAgainst(*base, r.result.strands); })));
            pyb::object regions = pyb::none();  // as transfer --json's "regions"
            if (returnReport) {
                const ScalpSphere& sphere = r.result.map->sphere();
                regions = toPython(runLong(threads, pyb::none(), [&](WorkInterrupter*) {
                    return compareStyleRegions(*base, r.result.strands, sphere.center, sphere.up, sphere.radius,
                                               r.result.head == "none" ? nullptr : &p.synth.head, nullptr, p.synth.front);
                }));
            }
            auto out = std::make_shared<StrandSet>(std::move(r.result.strands));
            if (!returnReport) return pyb::cast(out);
            pyb::dict report;
            report["compare"] = comparison;
            report["regions"] = regions;
            pyb::list clusters;
            for (const std::vector<std::int32_t>& c : r.result.clusterOf)
                clusters.append(pyb::array_t<std::int32_t>(pyb::ssize_t(c.size()), c.data()));
            report["cluster_of"] = clusters;
            report["base_label"] = pyb::array_t<std::int32_t>(pyb::ssize_t(r.baseLabel.size()), r.baseLabel.data());
            report["head_radius"] = pyb::make_tuple(r.detailsMap->radius(), r.result.map->radius());
            report["detail_scale"] = r.detailScale;
            report["length_ratio"] = r.lengthRatio;
            return pyb::make_tuple(out, report);
        },
        pyb::arg("details"), pyb::arg("base"), pyb::kw_only(), pyb::arg("guides") = transferDefaults.guides, pyb::arg("strands") = pyb::none(),
        pyb::arg("smoothing") = transferDefaults.smoothing, pyb::arg("smooth_base") = transferDefaults.smoothBase,
        pyb::arg("levels") = transferDefaults.synth.cluster.levels, pyb::arg("seed") = transferDefaults.synth.seed,
        pyb::arg("vertices") = transferDefaults.synth.vertices, pyb::arg("threshold") = transferDefaults.synth.cluster.threshold,
        pyb::arg("initial_clusters") = transferDefaults.synth.cluster.initialClusters, pyb::arg("components") = transferDefaults.synth.components,
        pyb::arg("detail") = detailBlendName(transferDefaults.synth.detailBlend), pyb::arg("detail_scale") = detailScaleName(transferDefaults.synth.detailScale),
        pyb::arg("match_balance") = transferDefaults.synth.match.balance, pyb::arg("match_candidates") = transferDefaults.synth.match.candidates,
        pyb::arg("match_place") = transferDefaults.synth.match.place,
        pyb::arg("refine") = transferDefaults.synth.refine, pyb::arg("refine_mode") = pyb::none(), pyb::arg("voxel_size") = transferDefaults.synth.voxelSize,
        pyb::arg("up") = pyb::none(), pyb::arg("front") = pyb::none(), pyb::arg("scalp") = pyb::none(), pyb::arg("measure") = false,
        pyb::arg("return_report") = false, pyb::arg("threads") = 0,
        pyb::arg("progress") = pyb::none(),
        R"doc(The base's global flow with the details' wisps and waves (Wang et al. 2009, §6): ``vdbhair transfer``.

docs/editing.md, explains every option and its measured default.

Args:
    details: Strands whose detail is taken.
    base: Strands whose coarsest level (smoothed, unless smooth_base=False) and wisps are kept.
    guides: the base's strands are the coarsest level as they are; finer roots spread over their region.
    strands: with guides, strands in the output.
    smoothing: sigma of the coarsest levels' smoothing, a fraction of their vertices.
    smooth_base: smooth the base's coarsest level too (False: the paper's rule).
    detail_scale: "arc-length" (curls keep their size, the strand runs the base's wisp), "index"
        (the paper's, vertex by vertex) or "strand".
    match_candidates: as synth's, 64 here (the two hairstyles' wisps differ more).
    match_place: as synth's, 0 here (two hairstyles' places are not one another's).
    measure: with return_report, the report's "compare" holds the output against the base, as
        ``vdbhair.compare(base, output)``.
    Other options as synth (front: the head's front for the report's "regions", which set the output
    beside the base, region by region).

Returns:
    Strands, or (Strands, report) with return_report.)doc");

    const CombParams combDefaults;
    m.def(
        "comb",
        [](const StrandsPtr& strands, const pyb::object& strokes, double smoothing, int levels, std::uint64_t seed, int vertices,
           double threshold, int initialClusters, std::optional<std::array<double, 3>> up, std::optional<PathArg> scalp,
           const pyb::object& head, const std::string& headPolicy, bool returnReport, int threads,
           const pyb::object& progress) -> pyb::object {
            const HeadArgument headArg(head, headPolicy);
            std::vector<CombStroke> list;
            if (isPathLike(strokes)) {
                list = readStrokes(pathString(strokes, "comb: strokes"));
            } else {
                if (!pyb::hasattr(strokes, "__iter__")) {
                    throw TypeError("comb: strokes must be a path to a strokes .json or a list of dicts, got " +
                                    std::string(pyb::str(strokes.get_type().attr("__name__"))));
                }
                for (const pyb::handle& h : strokes) {
                    const pyb::dict d = h.cast<pyb::dict>();
                    CombStroke st;
                    for (const pyb::handle& q : d["points"]) {
                        const auto xyz = q.cast<std::array<double, 3>>();
                        st.points.emplace_back(xyz[0], xyz[1], xyz[2]);
                    }
                    st.radius = d["radius"].cast<double>();
                    if (d.contains("strength")) st.strength = d["strength"].cast<double>();
                    validateStroke(st, list.size(), "comb");
                    list.push_back(std::move(st));
                }
            }
            CombParams p;
            p.smoothing = smoothing;
            setHierarchy(p.synth, levels, seed, vertices, threshold, initialClusters, up);
            p.validate("comb");
            CombResult r = runLong(threads, progress, [&](WorkInterrupter* interrupter) {
                openvdb::FloatGrid::Ptr grid = scalp ? readScalp(*scalp, interrupter) : nullptr;
                CombParams q = p;
                q.head = headArg.get("comb");
                return combHair(*strands, list, q, grid, true, interrupter);
            });
            auto out = std::make_shared<StrandSet>(std::move(r.strands));
            if (!returnReport) return pyb::cast(out);
            pyb::dict report;
            report["combed_clusters"] = r.stats.combedClusters;
            report["clusters"] = r.stats.clusters;
            report["moved_strands"] = r.stats.movedStrands;
            report["angle_before"] = r.stats.angleBefore;
            report["angle_after"] = r.stats.angleAfter;
            report["turning_before"] = r.stats.turningBefore;
            report["turning_after"] = r.stats.turningAfter;
            report["head"] = r.stats.head;
            report["head_deflected"] = r.stats.headDeflected;
            report["inside_head_before"] = r.stats.insideHeadBefore;
            report["inside_head_after"] = r.stats.insideHeadAfter;
            report["new_kinks"] = r.stats.newKinks;
            report["cluster"] = pyb::array_t<std::int32_t>(pyb::ssize_t(r.cluster.size()), r.cluster.data());
            return pyb::make_tuple(out, report);
        },
        pyb::arg("strands"), pyb::arg("strokes"), pyb::kw_only(), pyb::arg("smoothing") = combDefaults.smoothing,
        pyb::arg("levels") = combDefaults.synth.cluster.levels, pyb::arg("seed") = combDefaults.synth.seed,
        pyb::arg("vertices") = combDefaults.synth.vertices, pyb::arg("threshold") = combDefaults.synth.cluster.threshold,
        pyb::arg("initial_clusters") = combDefaults.synth.cluster.initialClusters, pyb::arg("up") = pyb::none(),
        pyb::arg("scalp") = pyb::none(), pyb::arg("head") = pyb::none(), pyb::arg("head_policy") = headPolicyName(kDefaultHeadPolicy),
        pyb::arg("return_report") = false, pyb::arg("threads") = 0, pyb::arg("progress") = pyb::none(),
        R"doc(Detail-preserving combing (Wang et al. 2009, §6): ``vdbhair comb``.

Args:
    strands: Strands to comb.
    strokes: a path to a stroke file, or a list of dicts {"points": [[x, y, z], ...], "radius": r, "strength": s}.
    smoothing: sigma of the strand directions the strokes turn, a fraction of the vertices.
    levels, seed, vertices, threshold, initial_clusters, up, scalp: the hierarchy, as synth.
    head: the head strands may not enter: None (scalp's level set if given, else a sphere fitted
        to the roots), "none", a mesh or .vdb level set path, or (x, y, z, r) a sphere.
    head_policy: "no-deeper" (no vertex goes deeper into the head than the input's) or "outside".

Returns:
    Strands (same vertices, attributes kept), or (Strands, report) with return_report.)doc");
}

} // namespace vdbhair::py
