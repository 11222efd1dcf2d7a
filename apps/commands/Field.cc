// vdbhair field IN -o OUT.vdb: strands to the robust tangent field (Wang et al. 2009, Eq. 9).
#include "../Command.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/field/Refine.h>
#include <vdbhair/field/TangentField.h>
#include <vdbhair/helicoid/HelicoidField.h>
#include <vdbhair/io/FileUtil.h>
#include <vdbhair/io/VdbFile.h>
#include <vdbhair/io/VdbStrandGrid.h>

#include <cctype>
#include <chrono>
#include <cmath>

namespace vdbhair::app {

namespace {

struct FieldCmdParams
{
    std::string input, output;
    // Defaults from the library's FieldParams (one home for each).
    double voxelSize = FieldParams{}.voxelSize;
    CLI::Option* voxelOpt = nullptr;  ///< whether --voxel-size was given
    int iterations = FieldParams{}.iterations;
    int levels = 1;
    std::uint64_t maxVoxels = FieldParams{}.maxVoxels;
    bool withStrands = false;
    bool helicoid = false;
    bool strict = false;
    ScalpOptions scalp;
    double densityReference = FieldParams{}.densityReference;
    std::string vectorName = "tangent";
};

int runField(const FieldCmdParams& p, const CommonOptions& common)
{
    if (p.output.empty()) throw ValueError("needs an output: -o OUT.vdb");
    if (fileExtension(p.output) != ".vdb") throw ValueError(p.output + ": the field is written as OpenVDB; the output must end in .vdb");
    const bool voxelGiven = p.voxelOpt && p.voxelOpt->count() > 0;
    if (voxelGiven && (!(p.voxelSize > 0.0) || !std::isfinite(p.voxelSize))) {
        throw ValueError("--voxel-size " + formatValue(p.voxelSize) + ": must be a positive finite length");
    }
    if (p.iterations < 1) throw ValueError("--iterations " + std::to_string(p.iterations) + ": must be at least 1");
    if (p.levels < 1 || p.levels > FieldParams::kMaxLevels) {
        throw ValueError("--levels " + std::to_string(p.levels) + ": must be between 1 and " + std::to_string(FieldParams::kMaxLevels));
    }
    if (p.helicoid && p.levels != 1) throw ValueError("--helicoid with --levels " + std::to_string(p.levels) + ": a helicoid field has one level; use --levels 1");
    if (p.helicoid && p.scalp.space != "world") throw ValueError("--helicoid with --space " + p.scalp.space + ": helicoid fields are world-space");
    if (p.densityReference < 0.0 || !std::isfinite(p.densityReference)) {
        throw ValueError("--density-reference " + formatValue(p.densityReference) + ": must be a positive length per unit volume (0 chooses it)");
    }
    if (p.vectorName.empty() || p.vectorName.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_") != std::string::npos ||
        std::isdigit(static_cast<unsigned char>(p.vectorName[0]))) {
        throw ValueError("--vector-name '" + p.vectorName + "': must be a valid attribute name (letters, digits, _; not starting with a digit)");
    }
    if (p.helicoid && p.vectorName != "tangent") throw ValueError("--helicoid with --vector-name " + p.vectorName + ": retrace --helicoid reads the vector grid 'tangent'");

    const StrandSet strands = loadStrands("field", p.input, common, p.strict);
    checkStrandLengths("field", p.input, strands, common, p.strict);
    FieldParams fp;
    fp.voxelSize = voxelGiven ? p.voxelSize : 0.0;
    fp.voxelSize = resolveVoxelSize(strands, fp);  // 0: the library's suggestion (reported below)
    fp.iterations = p.iterations;
    fp.maxVoxels = p.maxVoxels;
    fp.densityReference = p.densityReference;
    applyScalpOptions(p.scalp, strands, fp);

    const auto t0 = std::chrono::steady_clock::now();
    const std::vector<TangentField> fields = estimateTangentFieldLevels(strands, fp, p.levels, true, common.interrupter);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

    openvdb::GridCPtrVec grids;
    nlohmann::json gridsJson = nlohmann::json::array();
    for (const TangentField& f : fields) {
        if (p.vectorName != "tangent") {  // e.g. hair_direction: Blender's Cycles reserves 'tangent'
            const std::string name = f.tangent->getName();
            f.tangent->setName(p.vectorName + name.substr(std::string("tangent").size()));
        }
        for (const openvdb::GridBase::Ptr& g : {openvdb::GridBase::Ptr(f.tangent), openvdb::GridBase::Ptr(f.density), openvdb::GridBase::Ptr(f.hairLength)}) {
            g->insertMeta("vdbhair_source", openvdb::StringMetadata(p.input));
            grids.push_back(g);
            gridsJson.push_back({{"name", g->getName()}, {"voxel_size", g->voxelSize().x()}, {"active_voxels", g->activeVoxelCount()}});
        }
    }
    if (p.helicoid) {
        const HelicoidFieldGrids h = estimateHelicoidField(*fields[0].tangent, true, common.interrupter);
        for (const openvdb::GridBase::Ptr& g : {openvdb::GridBase::Ptr(h.k), openvdb::GridBase::Ptr(h.alpha),
                                                openvdb::GridBase::Ptr(h.frameT), openvdb::GridBase::Ptr(h.frameN)}) {
            grids.push_back(g);
            gridsJson.push_back({{"name", g->getName()}, {"voxel_size", g->voxelSize().x()}, {"active_voxels", g->activeVoxelCount()}});
        }
    }
    if (p.withStrands) grids.push_back(createStrandGrid(strands));
    {
        const Stage stage(common, "writing " + p.output);
        writeVdbGrids(p.output, grids, "field(" + p.output + ")");
    }

    if (common.json) {
        nlohmann::json j = {{"output", p.output}, {"strands", strands.numStrands()}, {"voxel_size", fp.voxelSize},
                            {"iterations", fp.iterations}, {"levels", p.levels}, {"space", fieldSpaceName(fp.space)},
                            {"grids", gridsJson}, {"seconds", seconds}};
        if (fp.space == FieldSpace::Scalp) {
            j["scalp"] = {{"center", {fp.scalp.center.x(), fp.scalp.center.y(), fp.scalp.center.z()}}, {"radius", fp.scalp.radius}};
        }
        printJson(j);
    } else if (!common.quiet) {
        std::cout << "field of " << strands.numStrands() << " strands, voxel size " << fp.voxelSize << " ("
                  << fieldSpaceName(fp.space) << " space), " << fp.iterations << " iteration(s), " << p.levels << " level(s):\n";
        for (const auto& g : gridsJson) {
            std::cout << "  " << g["name"].get<std::string>() << ": " << g["active_voxels"].get<std::uint64_t>()
                      << " active voxels of size " << g["voxel_size"].get<double>() << "\n";
        }
        std::cout << "wrote " << p.output << "\n";
    }
    return 0;
}

} // namespace

Command addFieldCommand(CLI::App& app, CommonOptions& common)
{
    auto params = std::make_shared<FieldCmdParams>();
    CLI::App* sub = app.add_subcommand("field", "Estimate the robust tangent field of a hairstyle (Wang et al. 2009, Eq. 9) as VDB grids");
    sub->add_option("input", params->input, "Strand file")->required();
    sub->add_option("-o,--output", params->output, "Output .vdb: grids 'tangent', 'density' (fog volume in [0,1]) and 'hair_length' (or *_level_<l>)")->required();
    params->voxelOpt = sub->add_option("--voxel-size", params->voxelSize, "Voxel size in world units (default: " + kSuggestedVoxelSizeHelp + ")");
    sub->add_option("--iterations", params->iterations, "Reweighting iterations of Eq. 9")->capture_default_str();
    sub->add_option("--levels", params->levels, "Levels: level l has voxel size h*2^l")->capture_default_str();
    sub->add_option("--max-voxels", params->maxVoxels, "Refuse voxel sizes whose voxel visits could exceed this")->capture_default_str();
    sub->add_option("--density-reference", params->densityReference,
                    "Hair length per unit volume (world units^-2) that 'density' maps to 1 (default: the 95th percentile of the hairstyle's)");
    sub->add_option("--vector-name", params->vectorName,
                    "Name of the direction grid; Blender's Cycles reserves 'tangent' for UV tangents, so use e.g. hair_direction for Cycles")
        ->capture_default_str();
    sub->add_flag("--helicoid", params->helicoid, "Also fit a helicoid per voxel: grids helicoid_k, helicoid_alpha, frame_T, frame_N");
    sub->add_flag("--with-strands", params->withStrands, "Also write the strands as the points grid 'strands'");
    sub->add_flag("--strict", params->strict, "Reject strands of fewer than 2 vertices instead of dropping them");
    addScalpOptions(sub, params->scalp);
    addCommonOptions(sub, common);
    sub->footer("Example: vdbhair field hair.hair -o field.vdb --voxel-size 0.5 --levels 3");
    return {sub, [params, &common] { return runField(*params, common); }, {{"maxVoxels", "--max-voxels"}}};
}

} // namespace vdbhair::app
