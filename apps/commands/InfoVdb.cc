// vdbhair info of a .vdb file (Info.h): its grids, or the strands of one points grid.
#include "Info.h"

#include <vdbhair/io/StrandIO.h>
#include <vdbhair/io/VdbInfo.h>
#include <vdbhair/io/VdbInspectJson.h>

namespace vdbhair::app {

using namespace info;

int infoVdbFile(const InfoParams& p, const CommonOptions& common)
{
    if (!p.grid.empty()) {
        ReadReport report;
        const StrandSummary s = summarizeStrands(readStrands(p.input, p.readOptions(common), &report));
        return printStrandSummary(p, s, report, common);
    }
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


} // namespace vdbhair::app
