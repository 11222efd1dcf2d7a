// vdbhair info FILE [--json]: what a strand file or a .vdb file holds; a .vdb file is InfoVdb.cc's.
#include "Info.h"
#include "../ParamOptions.h"

#include <vdbhair/io/FileUtil.h>
#include <vdbhair/io/StrandFileSummary.h>
#include <vdbhair/io/StrandIO.h>

#include <vdbhair/Exceptions.h>

#include <cstdio>

namespace vdbhair::app::info {

nlohmann::json vec3Json(const Vec3d& v) { return {v.x(), v.y(), v.z()}; }

std::string fmt(double v)
{
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.6g", v);
    return buf;
}

std::string fmtVec(const Vec3d& v) { return "(" + fmt(v.x()) + ", " + fmt(v.y()) + ", " + fmt(v.z()) + ")"; }

} // namespace vdbhair::app::info

namespace vdbhair::app {

using namespace info;

ReadOptions InfoParams::readOptions(const CommonOptions& common) const
{
    ReadOptions ropts = vdbhair::app::readOptions(common);
    if (!grid.empty()) ropts.vdbGrid = grid;
    return ropts;
}

namespace {

nlohmann::json histogramJson(const Histogram& h)
{
    return {{"lo", h.lo}, {"hi", h.hi}, {"counts", h.counts}, {"above", h.above}};
}

nlohmann::json statsJson(const StrandStatistics& st)
{
    auto range = [](const RangeStats& r) { return nlohmann::json{{"min", r.min}, {"mean", r.mean}, {"max", r.max}}; };
    return {{"length", histogramJson(st.length)},
            {"turning_deg", {{"range", range(st.turning)}, {"histogram", histogramJson(st.turningHist)}}},
            {"curvature", {{"range", range(st.curvature)}, {"p99", st.curvatureP99}, {"histogram", histogramJson(st.curvatureHist)}}},
            {"vertices_per_strand", histogramJson(st.verticesPerStrand)}};
}

/// One histogram as prose: its range and its counts, bin by bin.
void printHistogram(const std::string& name, const Histogram& h, const std::string& unit)
{
    std::cout << "  " << name << " [" << fmt(h.lo) << " .. " << fmt(h.hi) << (unit.empty() ? "" : " " + unit) << "] in "
              << h.counts.size() << " bins:";
    for (std::size_t c : h.counts) std::cout << " " << c;
    if (h.above) std::cout << " (+" << h.above << " above)";
    std::cout << "\n";
}

} // namespace

int printStrandSummary(const InfoParams& p, const StrandSummary& s, const ReadReport& report, const CommonOptions& common,
                       const StrandStatistics* stats)
{
    printWarnings("info", report, common);
    const Vec3d bmin = s.bbox.empty() ? Vec3d(0.0) : Vec3d(s.bbox.min.x(), s.bbox.min.y(), s.bbox.min.z());
    const Vec3d bmax = s.bbox.empty() ? Vec3d(0.0) : Vec3d(s.bbox.max.x(), s.bbox.max.y(), s.bbox.max.z());
    if (common.json) {
        printJson({{"kind", "strands"},
                   {"file", p.input},
                   {"grid", p.grid.empty() ? nlohmann::json(nullptr) : nlohmann::json(p.grid)},
                   {"format", formatName(strandFormatFromPath(p.input))},
                   {"strands", s.strands},
                   {"vertices", s.vertices},
                   {"bbox", {vec3Json(bmin), vec3Json(bmax)}},
                   {"meters_per_unit", s.metersPerUnit > 0.0 ? nlohmann::json(s.metersPerUnit) : nlohmann::json(nullptr)},
                   {"up_axis", s.upAxis ? nlohmann::json(std::string(1, s.upAxis)) : nlohmann::json(nullptr)},
                   {"length", {{"min", s.length.min}, {"mean", s.length.mean}, {"max", s.length.max}}},
                   {"vertices_per_strand",
                    {{"min", s.verticesPerStrand.min}, {"mean", s.verticesPerStrand.mean}, {"max", s.verticesPerStrand.max}}},
                   {"dropped_strands", report.droppedStrands},
                   {"stats", stats ? statsJson(*stats) : nlohmann::json(nullptr)}});
        return 0;
    }
    std::cout << p.input << (p.grid.empty() ? std::string() : " (grid '" + p.grid + "')") << ": "
              << formatName(strandFormatFromPath(p.input)) << " strands\n"
              << "  strands:             " << s.strands << "\n"
              << "  vertices:            " << s.vertices << "\n"
              << "  vertices per strand: min " << fmt(s.verticesPerStrand.min) << ", mean "
              << fmt(s.verticesPerStrand.mean) << ", max " << fmt(s.verticesPerStrand.max) << "\n"
              << "  strand length:       min " << fmt(s.length.min) << ", mean " << fmt(s.length.mean)
              << ", max " << fmt(s.length.max) << "\n"
              << "  bounding box:        " << fmtVec(bmin) << " .. " << fmtVec(bmax) << "\n"
              << "  unit:                " << (s.metersPerUnit > 0.0 ? fmt(s.metersPerUnit) + " m (declared by the file)" : std::string("not declared by the file")) << "\n"
              << "  up axis:             " << (s.upAxis ? std::string("+") + s.upAxis + " (declared by the file)" : std::string("not declared by the file")) << "\n";
    if (report.droppedStrands) std::cout << "  dropped strands:     " << report.droppedStrands << " (fewer than 2 vertices)\n";
    if (stats) {
        std::cout << "  turning per strand:  min " << fmt(stats->turning.min) << ", mean " << fmt(stats->turning.mean) << ", max "
                  << fmt(stats->turning.max) << " deg\n"
                  << "  curvature:           min " << fmt(stats->curvature.min) << ", mean " << fmt(stats->curvature.mean) << ", p99 "
                  << fmt(stats->curvatureP99) << ", max " << fmt(stats->curvature.max) << " per unit length\n";
        printHistogram("length", stats->length, "");
        printHistogram("turning", stats->turningHist, "deg");
        printHistogram("curvature", stats->curvatureHist, "per unit length");
        printHistogram("vertices per strand", stats->verticesPerStrand, "");
    }
    return 0;
}


Command addInfoCommand(CLI::App& app, CommonOptions& common)
{
    auto params = std::make_shared<InfoParams>();
    CLI::App* sub = addVerb(app, "info");
    sub->add_option("file", params->input, "A strand file (.hair .data .obj .ply .usda .usd .abc .tfx .bin .convdata) or a .vdb file")->required();
    addStrictOption(sub, common);
    sub->add_option("--grid", params->grid, "For a .vdb file: summarize the strands of this points grid (e.g. strands, strands_input) instead of listing the grids");
    sub->add_flag("--stats", params->stats, "Also histograms of strand length, turning (degrees per strand), curvature (per vertex) and vertices per strand");
    addParamOptions(sub, params->statsParams, strandStatsParameters());
    addCommonOptions(sub, common);
    addReadOptions(sub, common);
    sub->footer("Example: vdbhair info scenes/default/ponytail.hair --json");
    return {sub, [params, &common] {
                checkParamOptions(strandStatsParameters(), params->statsParams);
                if (params->stats) {
                    if (fileExtension(params->input) == ".vdb" && params->grid.empty()) {
                        throw ValueError("--stats of " + params->input + ": a .vdb needs --grid, the points grid holding the strands");
                    }
                    ReadReport report;
                    const StrandSet strands = readStrands(params->input, params->readOptions(common), &report);
                    const StrandStatistics stats = computeStrandStatistics(strands, params->statsParams.bins);
                    return printStrandSummary(*params, stats.summary, report, common, &stats);
                }
                if (fileExtension(params->input) == ".vdb") return infoVdbFile(*params, common);
                ReadReport report;
                const StrandSummary s = summarizeStrandFile(params->input, params->readOptions(common), &report);
                return printStrandSummary(*params, s, report, common);
            }};
}

} // namespace vdbhair::app
