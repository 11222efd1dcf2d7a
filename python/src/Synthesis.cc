// vdbhair.synth, transfer and comb: Wang et al.'s synthesis, detail transfer and combing.
#include "Common.h"
#include "Params.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/compare/HairComparison.h>
#include <vdbhair/field/Refine.h>
#include <vdbhair/io/MeshFile.h>
#include <vdbhair/scalp/ScalpSurface.h>
#include <vdbhair/synth/Comb.h>
#include <vdbhair/synth/HairTransfer.h>
#include <vdbhair/synth/StyleRegions.h>
#include <vdbhair/synth/Synthesis.h>
#include <vdbhair/synth/SynthJson.h>

#include <nlohmann/json.hpp>

#include <pybind11/stl.h>

#include <cmath>
#include <memory>
#include <optional>
#include <tuple>

namespace vdbhair::py {

namespace {

/// The help of the scalp keyword that synth, transfer and comb share (a file: each front end's own).
const char* const kScalpDoc = "a path to a scalp: .vdb with a level set 'surface', or a head mesh (.ply, .obj).";

/// The clusters of every output strand per level (the report's "cluster_of", Python's own: arrays).
pyb::list clusterArrays(const std::vector<std::vector<std::int32_t>>& clusterOf)
{
    pyb::list clusters;
    for (const std::vector<std::int32_t>& c : clusterOf) clusters.append(pyb::array_t<std::int32_t>(pyb::ssize_t(c.size()), c.data()));
    return clusters;
}

/// vdbhair.synth(example, **keywords): the declared parameters, then synth's own keywords.
pyb::object synthImpl(const StrandsPtr& example, const pyb::dict& kw)
{
    SynthParams p;
    std::vector<Vec3d> regionPoints;
    const auto region = kw["region"].cast<std::optional<pyb::array_t<double, pyb::array::c_style | pyb::array::forcecast>>>();
    if (region) {
        if (region->ndim() != 2 || region->shape(1) != 3) throw ValueError("synth: region must be an (N, 3) array of points");
        const auto r = region->unchecked<2>();
        regionPoints.reserve(std::size_t(r.shape(0)));
        for (pyb::ssize_t i = 0; i < r.shape(0); ++i) regionPoints.emplace_back(r(i, 0), r(i, 1), r(i, 2));
    }
    applyKeywords(synthParameters(), kw, p, "synth");
    const HeadArgument headArg(kw["head"], headPolicyName(kDefaultHeadPolicy));  // as --head, read with its policy
    if (p.strands > 0 && example->empty()) throw ValueError("synth: the example has no strands");
    p.validate("synth");
    const auto scalp = kw["scalp"].cast<std::optional<PathArg>>(), outputScalp = kw["output_scalp"].cast<std::optional<PathArg>>();
    if (p.outputTurn != 0.0 && !outputScalp) throw ValueError("synth: output_turn needs output_scalp");
    if (outputScalp && !region) throw ValueError("synth: output_scalp needs region=, the points where the hair grows on that head");
    const int threads = kw["threads"].cast<int>();
    const bool returnReport = kw["return_report"].cast<bool>();
    std::shared_ptr<const ScalpMap> other;
    SynthResult r = runLong(threads, kw["progress"], [&](WorkInterrupter* interrupter) {
        openvdb::FloatGrid::Ptr grid = scalp ? readScalp(*scalp, interrupter) : nullptr;
        if (outputScalp) {
            std::vector<Vec3f> pts(regionPoints.begin(), regionPoints.end());
            const openvdb::FloatGrid::Ptr otherGrid = readScalp(*outputScalp, interrupter);
            other = scalpMapOfPoints(pts, p.up, otherGrid);
            p.head = HeadObstacle::levelSet(otherGrid);  // the head the hair grows on (as the command)
        }
        if (const HeadObstacle given = headArg.get("synth"); !given.unset()) p.head = given;  // head= over that (as --head)
        return synthesizeHair(*example, p, grid, true, interrupter, region ? &regionPoints : nullptr, other);
    });
    if (!returnReport) return pyb::cast(std::make_shared<StrandSet>(std::move(r.strands)));
    // synth --json's report (SynthJson.h), with the clusters as arrays.
    const SynthMeasures m = runLong(threads, pyb::none(), [&](WorkInterrupter*) { return measureSynthesis(*example, r, p, other.get(), p.measure); });
    const SynthSources sources{scalp ? std::string(*scalp) : std::string(),
                               region ? "the " + std::to_string(regionPoints.size()) + " points of region=" : std::string(),
                               outputScalp ? std::string(*outputScalp) : std::string()};
    pyb::dict report = toPython(synthReport(*example, r, p, other.get(), sources, m));
    report["cluster_of"] = clusterArrays(r.clusterOf);
    return pyb::make_tuple(std::make_shared<StrandSet>(std::move(r.strands)), report);
}

/// vdbhair.transfer(details, base, **keywords): the declared parameters, then transfer's own keywords.
pyb::object transferImpl(const StrandsPtr& details, const StrandsPtr& base, const pyb::dict& kw)
{
    TransferParams p;
    const HeadArgument headArg(kw["head"], headPolicyName(kDefaultHeadPolicy));  // as --head, read with its policy
    applyKeywords(transferParameters(), kw, p, "transfer");
    if (p.strands > 0 && !p.guides) throw ValueError("transfer: strands: the output has the base's strands; strands needs guides=True");
    p.validate("transfer");
    const auto scalp = kw["scalp"].cast<std::optional<PathArg>>();
    const int threads = kw["threads"].cast<int>();
    const bool returnReport = kw["return_report"].cast<bool>();
    TransferResult r = runLong(threads, kw["progress"], [&](WorkInterrupter* interrupter) {
        openvdb::FloatGrid::Ptr grid = scalp ? readScalp(*scalp, interrupter) : nullptr;
        if (const HeadObstacle given = headArg.get("transfer"); !given.unset()) p.synth.head = given;  // as --head
        return transferHairstyle(*details, *base, p, grid, true, interrupter);
    });
    if (!returnReport) return pyb::cast(std::make_shared<StrandSet>(std::move(r.result.strands)));
    // transfer --json's report (SynthJson.h), with the clusters and BASE's labels as arrays.
    const TransferMeasures m = runLong(threads, pyb::none(), [&](WorkInterrupter*) { return measureTransfer(*details, *base, r, p, p.synth.measure); });
    pyb::dict report = toPython(transferReport(*base, r, p, m));
    report["cluster_of"] = clusterArrays(r.result.clusterOf);
    report["base_label"] = pyb::array_t<std::int32_t>(pyb::ssize_t(r.baseLabel.size()), r.baseLabel.data());
    return pyb::make_tuple(std::make_shared<StrandSet>(std::move(r.result.strands)), report);
}

/// vdbhair.comb(strands, strokes, **keywords): the declared parameters, then comb's own keywords.
pyb::object combImpl(const StrandsPtr& strands, const pyb::object& strokes, const pyb::dict& kw)
{
    CombParams p;
    applyKeywords(combParameters(), kw, p, "comb");
    const HeadArgument headArg(kw["head"], headPolicyName(p.headPolicy));
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
    p.validate("comb");
    const auto scalp = kw["scalp"].cast<std::optional<PathArg>>();
    CombResult r = runLong(kw["threads"].cast<int>(), kw["progress"], [&](WorkInterrupter* interrupter) {
        openvdb::FloatGrid::Ptr grid = scalp ? readScalp(*scalp, interrupter) : nullptr;
        CombParams q = p;
        q.head = headArg.get("comb");
        return combHair(*strands, list, q, grid, true, interrupter);
    });
    if (!kw["return_report"].cast<bool>()) return pyb::cast(std::make_shared<StrandSet>(std::move(r.strands)));
    // comb --json's report (SynthJson.h), with each strand's coarsest cluster as an array.
    pyb::dict report = toPython(combReport(r, list.size()));
    report["cluster"] = pyb::array_t<std::int32_t>(pyb::ssize_t(r.cluster.size()), r.cluster.data());
    return pyb::make_tuple(std::make_shared<StrandSet>(std::move(r.strands)), report);
}

} // namespace

void bindSynthesis(pyb::module_& m)
{
    defineVerb(m, "synth", {"example: vdbhair.Strands"}, synthParameters(),
               {{"scalp", "Optional[os.PathLike | str]", pyb::none(), kScalpDoc},
                {"region", "", pyb::none(),
                 "where the new hair grows, an (N, 3) array of points on the scalp (roots() positions, another hairstyle's roots); "
                 "None: the example's region. The count scales with the area."},
                {"output_scalp", "Optional[os.PathLike | str]", pyb::none(),
                 "a path to another head (scalp .vdb or mesh) that region= lies on: the hairstyle is made at the region's (u, v) "
                 "and moved onto it through scalp space."},
                {"head", "", pyb::none(),
                 "the head new hair may enter no deeper than the example's hair (``--head``): None (output_scalp's, else scalp's "
                 "surface, else the sphere fitted to the roots), \"none\" (no head), a path to a mesh (.ply, .obj) or a .vdb level "
                 "set, or a sphere (x, y, z, r)."},
                {"return_report", "bool", pyb::bool_(false),
                 "also return ``synth --json``'s report as a dict (less the file names and the seconds: levels, stages, head, statistics, "
                 "checks, regions, ...), with the cluster_of arrays per level."}},
               "A new hairstyle in the style of an example (Wang et al. 2009, §3-5): ``vdbhair synth``.\n\n"
               "Hierarchical clustering, PCA feature maps and texture optimization, cluster-oriented detail\n"
               "transfer and vector-field refinement per level; deterministic for a seed, the same for any\n"
               "thread count. docs/synthesis.md, explains every option and its measured default.",
               "    example: Strands (many: at least 4^(levels-1)).\n", "Strands, or (Strands, report) with return_report.",
               pyb::cpp_function(synthImpl, pyb::arg("example"), pyb::arg("keywords")));

    defineVerb(m, "transfer", {"details: vdbhair.Strands", "base: vdbhair.Strands"}, transferParameters(),
               {{"scalp", "Optional[os.PathLike | str]", pyb::none(), kScalpDoc},
                {"head", "", pyb::none(),
                 "the head new hair may enter no deeper than the base's hair (``--head``): None (scalp's surface, else the sphere "
                 "fitted to the base's roots), \"none\" (no head), a path to a mesh (.ply, .obj) or a .vdb level set, or a sphere (x, y, z, r)."},
                {"return_report", "bool", pyb::bool_(false),
                 "also return ``transfer --json``'s report as a dict (less the file names and the seconds), with the cluster_of arrays "
                 "per level and the base's coarsest cluster of each strand (base_label)."}},
               "The base's global flow with the details' wisps and waves (Wang et al. 2009, §6): ``vdbhair transfer``.\n\n"
               "docs/editing.md, explains every option and its measured default.",
               "    details: Strands whose detail is taken.\n"
               "    base: Strands whose coarsest level (smoothed, unless smooth_base=False) and wisps are kept.\n",
               "Strands, or (Strands, report) with return_report.",
               pyb::cpp_function(transferImpl, pyb::arg("details"), pyb::arg("base"), pyb::arg("keywords")));

    defineVerb(m, "comb", {"strands: vdbhair.Strands", "strokes"}, combParameters(),
               {{"scalp", "Optional[os.PathLike | str]", pyb::none(), kScalpDoc},
                {"head", "", pyb::none(),
                 "the head strands may not enter: None (scalp's level set if given, else a sphere fitted to the roots), \"none\", "
                 "a mesh or .vdb level set path, or (x, y, z, r) a sphere."},
                {"return_report", "bool", pyb::bool_(false),
                 "also return ``comb --json``'s report as a dict (less the file names and the seconds), with each strand's coarsest cluster (cluster)."}},
               "Detail-preserving combing (Wang et al. 2009, §6): ``vdbhair comb``.",
               "    strands: Strands to comb.\n"
               "    strokes: a path to a stroke file, or a list of dicts {\"points\": [[x, y, z], ...], \"radius\": r, \"strength\": s}.\n",
               "Strands (same vertices, attributes kept), or (Strands, report) with return_report.",
               pyb::cpp_function(combImpl, pyb::arg("strands"), pyb::arg("strokes"), pyb::arg("keywords")));
}

} // namespace vdbhair::py
