// vdbhair refine IN -o OUT: Wang et al.'s vector-field refinement, coarse level to fine.
#include "../RefineOptions.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/field/Refine.h>
#include <vdbhair/io/FileUtil.h>
#include <vdbhair/io/StrandIO.h>
#include <vdbhair/io/VdbFile.h>

#include <cmath>

namespace vdbhair::app {

RefineParams refineParamsFrom(const RefineCmdParams& p, const StrandSet& strands)
{
    RefineParams rp;
    const bool voxelGiven = p.voxelOpt && p.voxelOpt->count() > 0, stepGiven = p.stepOpt && p.stepOpt->count() > 0;
    if (voxelGiven && (!(p.voxelSize > 0.0) || !std::isfinite(p.voxelSize))) {
        throw ValueError("--voxel-size " + formatValue(p.voxelSize) + ": must be a positive finite length");
    }
    if (stepGiven && (!(p.step > 0.0) || !std::isfinite(p.step))) {
        throw ValueError("--step " + formatValue(p.step) + ": must be a positive finite length");
    }
    if (p.iterations < 1) throw ValueError("--iterations " + std::to_string(p.iterations) + ": must be at least 1");
    if (p.levels < 1 || p.levels > 16) throw ValueError("--levels " + std::to_string(p.levels) + ": must be between 1 and 16");
    rp.field.voxelSize = voxelGiven ? p.voxelSize : 0.0;
    rp.field.iterations = p.iterations;
    rp.field.maxVoxels = p.maxVoxels;
    rp.levels = p.levels;
    rp.trace.step = stepGiven ? p.step : 0.0;
    rp.trace.integrator = integratorFromName(p.integrator);
    if (p.margin < 0 || p.margin > 16) throw ValueError("--margin " + std::to_string(p.margin) + ": must be between 0 and 16 voxels");
    rp.trace.margin = p.margin;
    applyScalpOptions(p.scalp, strands, rp.field);
    return rp;
}

openvdb::GridCPtrVec fieldGrids(const RefineResult& r, const std::string& source)
{
    openvdb::GridCPtrVec grids;
    for (const TangentField& f : r.fields) {
        // hair_length follows density's name (density_level_l -> hair_length_level_l) and metadata.
        const std::string densityName = f.density->getName();
        f.hairLength->setName("hair_length" + densityName.substr(std::string("density").size()));
        for (const char* key : {"vdbhair_level", "vdbhair_levels"}) {
            if (const auto m = f.density->getMetadata<openvdb::Int32Metadata>(key)) f.hairLength->insertMeta(key, *m);
        }
        for (const openvdb::GridBase::Ptr& g : {openvdb::GridBase::Ptr(f.tangent), openvdb::GridBase::Ptr(f.density), openvdb::GridBase::Ptr(f.hairLength)}) {
            g->insertMeta("vdbhair_source", openvdb::StringMetadata(source));
            grids.push_back(g);
        }
    }
    return grids;
}

nlohmann::json refineReportJson(const RefineResult& r, const RefineParams& rp)
{
    nlohmann::json j = traceReportJson(r.stats, r.angleBefore, r.angleAfter, r.meanDisplacement);
    j["voxel_size"] = r.voxelSize;
    j["levels"] = rp.levels;
    j["iterations"] = rp.field.iterations;
    j["space"] = fieldSpaceName(rp.field.space);
    return j;
}

namespace {

int runRefine(const RefineCmdParams& p, const CommonOptions& common)
{
    strandFormatFromPath(p.output, /*forWriting=*/true);
    if (!p.saveField.empty() && fileExtension(p.saveField) != ".vdb") {
        throw ValueError("--save-field " + p.saveField + ": must end in .vdb");
    }
    const StrandSet strands = loadStrands("refine", p.input, common, p.strict);
    const RefineParams rp = refineParamsFrom(p, strands);
    const RefineResult r = refineStrands(strands, rp, true, common.interrupter);
    // Write the field first: if the strands' write fails, nothing half-done is claimed.
    {
        const Stage stage(common, "writing " + p.output);
        if (!p.saveField.empty()) writeVdbGrids(p.saveField, fieldGrids(r, p.input), "refine(" + p.saveField + ")");
        writeStrands(p.output, r.strands);
    }
    if (common.json) {
        nlohmann::json j = refineReportJson(r, rp);
        j["output"] = p.output;
        printJson(j);
    } else if (!common.quiet) {
        std::cout << "refined with " << rp.levels << " level(s), finest voxel size " << r.voxelSize << " ("
                  << fieldSpaceName(rp.field.space) << " space)\n";
        printTraceReport(r.stats, r.angleBefore, r.angleAfter, r.meanDisplacement);
        if (!p.saveField.empty()) std::cout << "wrote " << p.saveField << "\n";
        std::cout << "wrote " << p.output << "\n";
    }
    return 0;
}

} // namespace

void addRefineOptions(CLI::App* sub, RefineCmdParams& p)
{
    p.voxelOpt = sub->add_option("--voxel-size", p.voxelSize, "Finest voxel size in world units (default: twice the mean segment length)");
    sub->add_option("--levels", p.levels, "Levels, coarse (h*2^(n-1)) to fine (h)")->capture_default_str();
    sub->add_option("--iterations", p.iterations, "Reweighting iterations of Eq. 9")->capture_default_str();
    p.stepOpt = sub->add_option("--step", p.step, "Integration step in world units (default: half of each level's voxel)");
    sub->add_option("--integrator", p.integrator, "euler (the papers' choice), rk2 or rk4")->capture_default_str();
    sub->add_option("--margin", p.margin, "Voxels a strand may continue straight past the field's active region (0: stop there, the papers' rule)")->capture_default_str();
    sub->add_option("--max-voxels", p.maxVoxels, "Refuse voxel sizes whose voxel visits could exceed this")->capture_default_str();
    sub->add_flag("--strict", p.strict, "Reject strands of fewer than 2 vertices instead of dropping them");
    addScalpOptions(sub, p.scalp);
}

Command addRefineCommand(CLI::App& app, CommonOptions& common)
{
    auto params = std::make_shared<RefineCmdParams>();
    CLI::App* sub = app.add_subcommand("refine", "Refine a hairstyle through its own tangent field: estimate, retrace, repeat from coarse to fine");
    sub->add_option("input", params->input, "Strand file")->required();
    sub->add_option("-o,--output", params->output, "Output strand file (.hair .data .obj .ply .vdb)")->required();
    sub->add_option("--save-field", params->saveField, "Also write the fields used (tangent[_level_l], density[_level_l]) to this .vdb");
    addRefineOptions(sub, *params);
    addCommonOptions(sub, common);
    sub->footer("Example: vdbhair refine hair.hair -o refined.hair --levels 3 --save-field field.vdb --json");
    return {sub, [params, &common] { return runRefine(*params, common); }};
}

} // namespace vdbhair::app
