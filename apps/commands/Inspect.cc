// vdbhair inspect F.vdb [--json] [--grid NAME] [--slice x|y|z=WORLD -o S.png [--hsv] [--streamlines N]]:
// value statistics, tiles, memory, bounds, leaf fill and metadata in words; slices as images.
#include "../Command.h"
#include "../ParamOptions.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/io/FileUtil.h>
#include <vdbhair/io/VdbInspect.h>
#include <vdbhair/io/VdbInspectJson.h>
#include <vdbhair/render/SliceRenderer.h>

#include <cstdio>

namespace vdbhair::app {

namespace {

/// The command line of inspect: its declared parameters (inspectParameters()) are options; the
/// file and the image's path are the command line's own.
struct InspectCmdParams
{
    std::string input, output;
    InspectParams inspect;
};

std::string g6(double v)
{
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.6g", v);
    return buf;
}

std::string pct(double share)
{
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.3g%%", 100.0 * share);
    return buf;
}

std::string vec3(const Vec3d& v) { return "(" + g6(v.x()) + ", " + g6(v.y()) + ", " + g6(v.z()) + ")"; }

void printReport(const GridReport& r)
{
    const GridInfo& g = r.info;
    std::cout << "grid '" << g.name << "': " << g.valueType << " (" << g.type << "), class " << g.gridClass;
    if (!g.vectorType.empty()) std::cout << ", vector type " << g.vectorType;
    std::cout << "\n";
    if (!r.explanation.empty()) std::cout << "  " << r.explanation << "\n";
    const bool uniform = g.voxelSize.x() == g.voxelSize.y() && g.voxelSize.x() == g.voxelSize.z();
    std::cout << "  voxels    " << g.activeVoxels << " active in " << g.leafNodes << " leaves";
    if (g.leafNodes) {
        std::cout << " (fill: mean " << pct(r.leafFillMean) << ", min " << pct(r.leafFillMin) << ", max " << pct(r.leafFillMax)
                  << "; " << pct(r.leafFullShare) << " of leaves full)";
    }
    std::cout << "\n  tiles     " << g.activeTiles << " active (" << r.tilesByLevel[0] << " of 4096^3 voxels, " << r.tilesByLevel[1]
              << " of 128^3, " << r.tilesByLevel[2] << " of 8^3); " << r.internalNodes << " internal nodes\n";
    std::cout << "  memory    " << g6(double(g.memoryBytes) / (1 << 20)) << " MiB";
    if (g.activeVoxels) std::cout << " (" << g6(double(g.memoryBytes) / double(g.activeVoxels)) << " bytes per active voxel)";
    std::cout << "\n  voxel     size " << (uniform ? g6(g.voxelSize.x()) : vec3(g.voxelSize)) << (g.linear ? "" : " (non-linear transform)") << "\n";
    if (r.emptyIndexBBox) {
        std::cout << "  bounds    (no active voxels)\n";
    } else {
        std::cout << "  bounds    index (" << r.indexMin[0] << ", " << r.indexMin[1] << ", " << r.indexMin[2] << ") .. (" << r.indexMax[0]
                  << ", " << r.indexMax[1] << ", " << r.indexMax[2] << "); world " << vec3(g.bboxMin) << " .. " << vec3(g.bboxMax) << "\n";
    }
    const ValueStats& s = r.values;
    auto line = [&](const char* label) {
        std::cout << "  " << label << "min " << g6(s.min) << ", max " << g6(s.max) << ", mean " << g6(s.mean) << ", std " << g6(s.stddev)
                  << "; 1st percentile " << g6(s.p01) << ", median " << g6(s.p50) << ", 99th " << g6(s.p99) << "\n";
    };
    if (r.isVector && s.count) {
        line("lengths   ");
        std::cout << "  vectors   " << pct(r.unitShare) << " unit length (within 1e-3), " << pct(r.zeroShare) << " zero; mean "
                  << vec3(r.meanVector) << ", coherence " << g6(r.coherence) << " (1: all parallel, 0: no common direction)\n";
    } else if (r.isScalar && s.count) {
        line("values    ");
        std::cout << "  zeros     " << pct(r.zeroShare) << " of active values\n";
    } else if (g.isPoints) {
        std::cout << "  points    " << g.pointCount << "; per active voxel min " << g6(s.min) << ", mean " << g6(s.mean) << ", max " << g6(s.max)
                  << "; attributes";
        for (const PointAttributeInfo& a : g.attributes) std::cout << " " << a.name << " (" << a.valueType << ", " << a.codec << ")";
        std::cout << "; groups";
        if (g.groups.empty()) std::cout << " (none)";
        for (const std::string& name : g.groups) std::cout << " " << name;
        std::cout << "\n";
    }
    if (!g.metadata.empty()) {
        std::cout << "  metadata ";
        for (std::size_t i = 0; i < g.metadata.size(); ++i) {
            std::cout << (i ? "\n            " : " ") << g.metadata[i].name << " = " << metaValueString(g.metadata[i], kListedMetaChars);
        }
        std::cout << "\n";
    }
}

int runInspect(const InspectCmdParams& cmd, const CommonOptions& common)
{
    const InspectParams& p = cmd.inspect;
    checkParamOptions(inspectParameters(), p);
    if (fileExtension(cmd.input) != ".vdb") throw ValueError(cmd.input + ": inspect reads .vdb files (use 'vdbhair info' for strand files)");
    const SliceParams sp = inspectSlice(p, cmd.output, "");
    const std::vector<GridReport> reports = inspectVdbFile(cmd.input, p.grid);
    nlohmann::json sliceJson;
    if (!p.slice.empty()) {
        const std::string name = chooseSliceGrid(reports, p.grid, cmd.input);
        const SliceResult res = renderSlice(cmd.input, name, sp);
        writeImage(cmd.output, res.image);
        sliceJson = {{"output", cmd.output}, {"grid", name}, {"axis", std::string(1, char('x' + sp.axis))}, {"world", sp.world},
                     {"index_plane", res.indexPlane}, {"active_voxels", res.activeVoxels}, {"range", {res.lo, res.hi}},
                     {"streamlines", res.streamlinesDrawn}, {"width", res.image.width}, {"height", res.image.height}};
        if (!common.json && !common.quiet) {
            std::cout << "wrote " << cmd.output << ": grid '" << name << "' at " << char('x' + sp.axis) << " = " << g6(sp.world) << " (voxel layer "
                      << res.indexPlane << ", " << res.activeVoxels << " active voxels, range " << g6(res.lo) << " .. " << g6(res.hi);
            if (res.streamlinesDrawn) std::cout << ", " << res.streamlinesDrawn << " streamlines";
            std::cout << ")\n";
        }
    }
    if (common.json) {
        nlohmann::json arr = nlohmann::json::array();
        for (const GridReport& r : reports) arr.push_back(gridReportJson(r));
        nlohmann::json out = {{"kind", "vdb"}, {"file", cmd.input}, {"grids", arr}};
        if (!sliceJson.is_null()) out["slice"] = sliceJson;
        printJson(out);
        return 0;
    }
    if (p.slice.empty()) {
        std::cout << cmd.input << ": OpenVDB file with " << reports.size() << (p.grid.empty() ? " grid" : " grid shown") << (reports.size() == 1 ? "" : "s") << "\n";
        for (const GridReport& r : reports) printReport(r);
    }
    return 0;
}

} // namespace

Command addInspectCommand(CLI::App& app, CommonOptions& common)
{
    auto params = std::make_shared<InspectCmdParams>();
    CLI::App* sub = addVerb(app, "inspect");
    sub->add_option("file", params->input, "A .vdb file")->required();
    sub->add_option("-o,--output", params->output, "The slice image (.png, .exr, .jpg)");
    addParamOptions(sub, params->inspect, inspectParameters());
    addCommonOptions(sub, common);
    sub->footer("Examples: vdbhair inspect field.vdb\n"
                "          vdbhair inspect field.vdb --slice z=0 -o slice.png --hsv --streamlines 300");
    return {sub, [params, &common] { return runInspect(*params, common); }};
}

} // namespace vdbhair::app
