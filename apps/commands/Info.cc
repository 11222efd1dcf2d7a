// vdbhair info FILE [--json]: what a strand file or a .vdb file holds.
#include "../Command.h"

#include <vdbhair/io/FileUtil.h>
#include <vdbhair/io/StrandFileSummary.h>
#include <vdbhair/io/StrandIO.h>
#include <vdbhair/io/VdbInfo.h>
#include <vdbhair/strands/Measures.h>

#include <cstdio>
#include <sstream>

namespace vdbhair::app {

namespace {

struct InfoParams
{
    std::string input;
    bool strict = false;
    std::string grid;  ///< a .vdb's points grid to summarize as strands; empty: list every grid
};

nlohmann::json vec3Json(const Vec3d& v) { return {v.x(), v.y(), v.z()}; }

nlohmann::json metaJson(const MetaValue& m)
{
    return std::visit([](const auto& v) { return nlohmann::json(v); }, m.value);
}

std::string fmt(double v)
{
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.6g", v);
    return buf;
}

std::string fmtVec(const Vec3d& v) { return "(" + fmt(v.x()) + ", " + fmt(v.y()) + ", " + fmt(v.z()) + ")"; }

int infoStrands(const InfoParams& p, const CommonOptions& common)
{
    ReadOptions ropts;
    if (p.strict) ropts.shortStrands = ShortStrandPolicy::Reject;
    if (!p.grid.empty()) ropts.vdbGrid = p.grid;
    ReadReport report;
    const StrandSummary s = summarizeStrandFile(p.input, ropts, &report);
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
                   {"length", {{"min", s.length.min}, {"mean", s.length.mean}, {"max", s.length.max}}},
                   {"vertices_per_strand",
                    {{"min", s.verticesPerStrand.min}, {"mean", s.verticesPerStrand.mean}, {"max", s.verticesPerStrand.max}}},
                   {"dropped_strands", report.droppedStrands}});
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
              << "  bounding box:        " << fmtVec(bmin) << " .. " << fmtVec(bmax) << "\n";
    if (report.droppedStrands) std::cout << "  dropped strands:     " << report.droppedStrands << " (fewer than 2 vertices)\n";
    return 0;
}

} // namespace

nlohmann::json gridInfoJson(const GridInfo& g)
{
    nlohmann::json meta = nlohmann::json::object();
    for (const MetaValue& m : g.metadata) meta[m.name] = metaJson(m);
    nlohmann::json j = {
        {"name", g.name},
        {"type", g.type},
        {"value_type", g.valueType},
        {"class", g.gridClass},
        {"vector_type", g.vectorType.empty() ? nlohmann::json(nullptr) : nlohmann::json(g.vectorType)},
        {"voxel_size", (g.voxelSize.x() == g.voxelSize.y() && g.voxelSize.x() == g.voxelSize.z())
                           ? nlohmann::json(g.voxelSize.x()) : vec3Json(g.voxelSize)},
        {"active_voxels", g.activeVoxels},
        {"active_tiles", g.activeTiles},
        {"leaf_nodes", g.leafNodes},
        {"memory_bytes", g.memoryBytes},
        {"bbox", g.emptyBBox ? nlohmann::json(nullptr) : nlohmann::json({vec3Json(g.bboxMin), vec3Json(g.bboxMax)})},
        {"metadata", meta}};
    if (g.isPoints) {
        nlohmann::json attrs = nlohmann::json::array();
        for (const PointAttributeInfo& a : g.attributes) attrs.push_back({{"name", a.name}, {"type", a.valueType}, {"codec", a.codec}});
        j["points"] = {{"count", g.pointCount}, {"attributes", attrs}, {"groups", g.groups}};
    }
    return j;
}

namespace {

int infoVdb(const InfoParams& p, const CommonOptions& common)
{
    const std::vector<GridInfo> grids = describeVdbFile(p.input);
    if (common.json) {
        nlohmann::json arr = nlohmann::json::array();
        for (const GridInfo& g : grids) {
            arr.push_back(gridInfoJson(g));
        }
        printJson({{"kind", "vdb"}, {"file", p.input}, {"grids", arr}});
        return 0;
    }
    std::cout << p.input << ": OpenVDB file with " << grids.size() << " grid" << (grids.size() == 1 ? "" : "s") << "\n";
    for (const GridInfo& g : grids) {
        std::cout << "  grid '" << g.name << "': " << g.valueType << " (" << g.type << "), class " << g.gridClass;
        if (!g.vectorType.empty()) std::cout << ", vector type " << g.vectorType;
        std::cout << "\n    voxel size " << (g.voxelSize.x() == g.voxelSize.y() && g.voxelSize.x() == g.voxelSize.z() ? fmt(g.voxelSize.x()) : fmtVec(g.voxelSize))
                  << (g.linear ? "" : " (non-linear transform)") << ", " << g.activeVoxels << " active voxels, "
                  << g.activeTiles << " active tiles, " << g.leafNodes << " leaf nodes, " << fmt(double(g.memoryBytes) / (1 << 20)) << " MiB\n";
        std::cout << "    bounding box " << (g.emptyBBox ? std::string("(empty)") : fmtVec(g.bboxMin) + " .. " + fmtVec(g.bboxMax)) << "\n";
        if (g.isPoints) {
            std::cout << "    points " << g.pointCount << "; attributes";
            for (const PointAttributeInfo& a : g.attributes) std::cout << " " << a.name << " (" << a.valueType << ", " << a.codec << ")";
            std::cout << "; groups";
            if (g.groups.empty()) std::cout << " (none)";
            for (const std::string& name : g.groups) std::cout << " " << name;
            std::cout << "\n";
        }
        for (const MetaValue& m : g.metadata) std::cout << "    " << m.name << " = " << metaValueString(m, kListedMetaChars) << "\n";
    }
    return 0;
}

} // namespace

Command addInfoCommand(CLI::App& app, CommonOptions& common)
{
    auto params = std::make_shared<InfoParams>();
    CLI::App* sub = app.add_subcommand("info", "Summarize a strand file or list the grids of a .vdb file");
    sub->add_option("file", params->input, "A strand file (.hair .data .obj .ply .usda .tfx .bin .convdata) or a .vdb file")->required();
    sub->add_flag("--strict", params->strict, "Reject strands of fewer than 2 vertices instead of dropping them");
    sub->add_option("--grid", params->grid, "For a .vdb file: summarize the strands of this points grid (e.g. strands, strands_input) instead of listing the grids");
    addCommonOptions(sub, common);
    sub->footer("Example: vdbhair info scenes/default/ponytail.hair --json");
    return {sub, [params, &common] {
                if (fileExtension(params->input) == ".vdb" && params->grid.empty()) {
                    return infoVdb(*params, common);
                }
                return infoStrands(*params, common);
            }};
}

} // namespace vdbhair::app
