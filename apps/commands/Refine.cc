// vdbhair refine IN -o OUT: Wang et al.'s vector-field refinement, coarse level to fine.
#include "../ParamOptions.h"
#include "../RefineOptions.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/compare/HairComparison.h>
#include <vdbhair/field/Refine.h>
#include <vdbhair/io/FileUtil.h>
#include <vdbhair/io/StrandIO.h>
#include <vdbhair/io/VdbFile.h>

#include <cmath>

namespace vdbhair::app {

RefineParams refineParamsFrom(const RefineCmdParams& p, const StrandSet& strands, const CommonOptions& common)
{
    RefineParams rp = p.refine;
    checkParamOptions(refineParameters(), rp);
    rp.validate("option");  // the library's rules across parameters (ParamErrors: run() spells them as flags)
    // A scalp given as a sphere or a level set is also the head the strands keep out of, unless
    // --head says otherwise.
    const openvdb::FloatGrid::Ptr surface = applyScalpOptions(p.scalp, strands, rp.field, common);
    const std::vector<double> sphere = p.scalp.sphere();
    rp.head = headFromOptions(p.head, surface ? HeadObstacle::levelSet(surface, rp.headPolicy)
                                      : sphere.empty() ? HeadObstacle()
                                      : HeadObstacle::sphere(rp.field.scalp.center, rp.field.scalp.radius, rp.headPolicy));
    return rp;
}

openvdb::GridCPtrVec fieldGrids(const RefineResult& r, const std::string& source)
{
    openvdb::GridCPtrVec grids;
    for (const TangentField& f : r.fields) {
        for (const openvdb::GridBase::ConstPtr& cg : f.grids()) {
            // The grids are this result's own; the source is stamped as they are handed out for writing.
            std::const_pointer_cast<openvdb::GridBase>(cg)->insertMeta("vdbhair_source", openvdb::StringMetadata(source));
            grids.push_back(cg);
        }
    }
    return grids;
}

void printRefineReport(const RefineResult& r, const RefineParams& rp)
{
    std::cout << "refined " << r.strands.numStrands() << " strands (" << refineModeName(rp.mode) << " mode) with " << rp.levels
              << " level(s), finest voxel size " << r.voxelSize << " (" << fieldSpaceName(rp.field.space) << " space); head: "
              << r.head.describe() << "\n";
    for (std::size_t l = r.levels.size(); l-- > 0;) {
        const RefineLevel& lv = r.levels[l];
        std::cout << "level " << l << " (voxel " << lv.voxelSize << "): ";
        if (rp.mode == RefineMode::Consistent) {
            std::cout << lv.consistency.corrected << " strands corrected where they strayed from the flow, "
                      << lv.consistency.pushedOut << " segments kept out of the head, " << lv.consistency.reverted
                      << " left as they were (their correction left the hair)\n";
        } else {
            std::cout << lv.trace.fullLength << " full length, " << lv.trace.vanished << " stopped where the field vanished, "
                      << lv.trace.leftField << " left the field\n";
        }
    }
    if (!rp.measure) return;
    const RefineMeasures& m = r.levels.front().measures;
    std::cout << "against the input: " << m.fullLength << " of " << m.strands << " strands at full length, " << m.leftVolume
              << " leave the hair volume, vertices inside the head " << m.insideHeadBefore << " before and " << m.insideHeadAfter
              << " after\n"
              << "curvature kept " << 100.0 * m.curvatureKept8 << " % at 8 segments (" << 100.0 * m.curvatureKeptVertex
              << " % at the vertices), tips in place " << 100.0 * m.tipOccupancy << " %\n"
              << "displacement " << m.displacementMean << " voxels mean, " << m.displacementP95 << " at the 95th percentile; "
              << "coherence " << m.coherenceBefore << " before, " << m.coherenceAfter << " after\n";
}

namespace {

int runRefine(const RefineCmdParams& p, const CommonOptions& common)
{
    strandFormatFromPath(p.output, /*forWriting=*/true);
    if (!p.saveField.empty() && fileExtension(p.saveField) != ".vdb") {
        throw ValueError("--save-field " + p.saveField + ": must end in .vdb");
    }
    StrandSet strands = loadStrands("refine", p.input, common);
    checkStrandLengths("refine", p.input, strands, common);
    const RefineParams rp = refineParamsFrom(p, strands, common);
    // Without --measure the input is not needed again: its storage may take the output
    // (refineStrands(StrandSet&&)); with it, the output is compared with it (`vdbhair compare`).
    StrandSet input;
    if (rp.measure) input = strands;
    const RefineResult r = refineStrands(std::move(strands), rp, true, common.interrupter);
    HairComparison comparison;
    if (rp.measure) {
        const Stage stage(common, "comparing with the input");
        comparison = measureAgainst(input, r.strands, &r.head);
    }
    // Write the field first: if the strands' write fails, nothing half-done is claimed.
    {
        const Stage stage(common, "writing " + p.output);
        if (!p.saveField.empty()) writeVdbGrids(p.saveField, fieldGrids(r, p.input), "refine(" + p.saveField + ")");
        writeStrands(p.output, r.strands);
    }
    if (common.json) {
        nlohmann::json j = refineReport(r, rp);
        j["output"] = p.output;
        if (rp.measure) j["compare"] = toJson(comparison);
        printJson(j);
    } else if (!common.quiet) {
        printRefineReport(r, rp);
        if (rp.measure) {
            std::cout << "compared with the input (vdbhair compare): " << summaryLine(comparison) << "\n";
        }
        if (!p.saveField.empty()) std::cout << "wrote " << p.saveField << "\n";
        std::cout << "wrote " << p.output << "\n";
    }
    return 0;
}

} // namespace

void addRefineOptions(CLI::App* sub, RefineCmdParams& p, const std::vector<std::string>& skip)
{
    addParamOptions(sub, p.refine, refineParameters(), skip);
    addHeadOptions(sub, p.head, p.refine.headPolicy, "--scalp's sphere if given, else a sphere fitted to the roots");
    addScalpOptions(sub, p.scalp);
}

Command addRefineCommand(CLI::App& app, CommonOptions& common)
{
    auto params = std::make_shared<RefineCmdParams>();
    CLI::App* sub = addVerb(app, "refine");
    sub->add_option("input", params->input, "Strand file")->required();
    sub->add_option("-o,--output", params->output, "Output strand file (.hair .data .obj .ply .vdb)")->required();
    sub->add_option("--save-field", params->saveField, "Also write the fields used (tangent[_level_l], density[_level_l]) to this .vdb");
    addRefineOptions(sub, *params);
    addStrictOption(sub, common);
    addCommonOptions(sub, common);
    addReadOptions(sub, common);
    sub->footer("Example: vdbhair refine hair.hair -o refined.hair --levels 3 --save-field field.vdb --measure --json");
    return {sub, [params, &common] { return runRefine(*params, common); }};
}

} // namespace vdbhair::app
