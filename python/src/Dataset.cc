// Bindings of the dataset toolbox: vdbhair.prepare() (`vdbhair prepare`) and
// vdbhair.strand_statistics() (`vdbhair info --stats`).
#include "Common.h"
#include "Params.h"

#include <vdbhair/dataset/Prepare.h>
#include <vdbhair/io/MeshFile.h>
#include <vdbhair/strands/StrandStats.h>

#include <nlohmann/json.hpp>

#include <pybind11/stl.h>

#include <memory>
#include <optional>

namespace vdbhair::py {

namespace {


/// A report's JSON as Python objects (the command line's keys and values).
pyb::object fromJson(const nlohmann::json& j)
{
    return pyb::module_::import("json").attr("loads")(j.dump());
}

nlohmann::json histogramJson(const Histogram& h)
{
    return {{"lo", h.lo}, {"hi", h.hi}, {"counts", h.counts}, {"above", h.above}};
}

/// prepare: a hairstyle made ready for a dataset (prepareParameters()).
void definePrepare(pyb::module_& m)
{
    auto prepareImpl = [](const StrandsPtr& strands, const pyb::dict& kw) {
        PrepareParams p;
        applyKeywords(prepareParameters(), kw, p, "prepare");
        try {
            p.validate();
        } catch (const ValueError& e) {
            throw ValueError(std::string("prepare: ") + e.what());
        }
        const pyb::object headArg = kw["head"], alignToArg = kw["align_to"];
        const std::optional<std::string> headPath = headArg.is_none() ? std::nullopt : std::optional<std::string>(pathString(headArg, "head"));
        const std::optional<std::string> alignPath =
            alignToArg.is_none() ? std::nullopt : std::optional<std::string>(pathString(alignToArg, "align_to"));
        if (alignPath && !headPath) throw ValueError("prepare: align_to needs head=, the groom's own head mesh: that head is fitted to align_to");
        const HeadArgument fix(kw["fix_penetration"], "outside");
        auto result = runLong(kw["threads"].cast<int>(), kw["progress"], [&](WorkInterrupter*) {
            StrandSet out = *strands;
            TriangleMesh head, target;
            if (headPath) head = readTriangleMesh(*headPath);
            if (alignPath) target = readTriangleMesh(*alignPath);
            const HeadObstacle obstacle = fix.get("prepare");
            const bool fixing = !obstacle.unset() && !obstacle.empty();
            PrepareReport r = prepareStrands(out, p, headPath ? &head : nullptr, alignPath ? &target : nullptr, fixing ? &obstacle : nullptr);
            return std::make_pair(std::make_shared<StrandSet>(std::move(out)), toJson(r));
        });
        return pyb::make_tuple(result.first, fromJson(result.second));
    };
    defineVerb(m, "prepare", {"strands: vdbhair.Strands"}, prepareParameters(),
               {{"head", "", pyb::none(), "the groom's own head mesh (a path to a .ply or .obj), the source of the alignment."},
                {"align_to", "", pyb::none(),
                 "a common head mesh (a path): head is fitted onto it by a similarity transform (Umeyama on vertex pairs for two "
                 "copies of one mesh, else trimmed ICP) and the strands move with it."},
                {"fix_penetration", "", pyb::none(),
                 "None, a head (a path to a mesh or a .vdb level set) or (x, y, z, r), a sphere, in the output's frame: strands "
                 "that enter it are bent out, lengths kept."}},
               "Make a hairstyle ready for a dataset (``vdbhair prepare IN OUT --json``): keep ``count``\n"
               "strands with evenly spread roots, move the groom onto a common head, resample every strand to\n"
               "``points`` vertices, push strands out of a head, in that order (the input is not changed).",
               "    strands: the Strands.\n",
               "(Strands, dict): the prepared strands and the command line's report (strands, vertices,\n"
               "    subsample, align with scale, rotation, translation, matrix and residual_rms, fix_penetration).",
               pyb::cpp_function(prepareImpl, pyb::arg("strands"), pyb::arg("keywords")));
}

} // namespace

void bindDataset(pyb::module_& m)
{
    definePrepare(m);

    // strand_statistics: the histograms of `info --stats` (strandStatsParameters()).
    auto statisticsImpl = [](const StrandsPtr& strands, const pyb::dict& kw) {
        StrandStatsParams p;
        applyKeywords(strandStatsParameters(), kw, p, "strand_statistics");
        const StrandStatistics s = runLong(kw["threads"].cast<int>(), kw["progress"], [&](WorkInterrupter*) {
            return computeStrandStatistics(*strands, p.bins);
        });
        auto range = [](const RangeStats& r) { return nlohmann::json{{"min", r.min}, {"mean", r.mean}, {"max", r.max}}; };
        const nlohmann::json j = {{"length", histogramJson(s.length)},
                                  {"turning_deg", {{"range", range(s.turning)}, {"histogram", histogramJson(s.turningHist)}}},
                                  {"curvature", {{"range", range(s.curvature)}, {"p99", s.curvatureP99}, {"histogram", histogramJson(s.curvatureHist)}}},
                                  {"vertices_per_strand", histogramJson(s.verticesPerStrand)}};
        return fromJson(j);
    };
    defineVerb(m, "strand_statistics", {"strands: vdbhair.Strands"}, strandStatsParameters(), {},
               "Histograms of a hairstyle (``vdbhair info --stats --json``'s \"stats\"): strand length,\n"
               "turning per strand (degrees), curvature per vertex (over [0, its 99th percentile], the rest\n"
               "counted in \"above\") and vertices per strand.",
               "    strands: a Strands.\n",
               "a dict: length, turning_deg (range, histogram), curvature (range, p99, histogram) and\n"
               "    vertices_per_strand, each histogram {\"lo\", \"hi\", \"counts\", \"above\"}.",
               pyb::cpp_function(statisticsImpl, pyb::arg("strands"), pyb::arg("keywords")));
}

} // namespace vdbhair::py
