// vdbhair field IN -o OUT.vdb: strands to the robust tangent field (Wang et al. 2009, Eq. 9).
#include "../Command.h"
#include "../ParamOptions.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/field/DenseArray.h>
#include <vdbhair/field/FieldJson.h>
#include <vdbhair/field/Refine.h>
#include <vdbhair/field/TangentField.h>
#include <vdbhair/helicoid/HelicoidField.h>
#include <vdbhair/io/FileUtil.h>
#include <vdbhair/io/NpyFile.h>
#include <vdbhair/io/VdbFile.h>
#include <vdbhair/io/VdbStrandGrid.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>

namespace vdbhair::app {

namespace {

struct FieldCmdParams
{
    std::string input, output;
    FieldLevelsParams params;  ///< its declared parameters (fieldLevelsParameters()) are options
    bool withStrands = false;
    bool helicoid = false;
    ScalpOptions scalp;
    std::string vectorName = "tangent";
    std::string dense;                       ///< --dense OUT.npy: the orientation volume
    std::vector<double> denseBox;            ///< x0,y0,z0,x1,y1,z1 (world units)
    std::vector<int> denseSize{kDefaultDenseShape.begin(), kDefaultDenseShape.end()};  ///< D,H,W: samples along z, y, x
};

/// --dense-box and --dense-size as a DenseBox (DenseArray.h), checked.
DenseBox denseBoxOption(const FieldCmdParams& p)
{
    if (p.denseBox.size() != 6) throw ValueError("--dense needs --dense-box X0,Y0,Z0,X1,Y1,Z1 (world units): one box for every hairstyle of a dataset");
    DenseBox box;
    box.worldMin = openvdb::Vec3d(p.denseBox[0], p.denseBox[1], p.denseBox[2]);
    box.worldMax = openvdb::Vec3d(p.denseBox[3], p.denseBox[4], p.denseBox[5]);
    for (int a = 0; a < 3; ++a) {
        if (!std::isfinite(box.worldMin[a]) || !std::isfinite(box.worldMax[a]) || !(box.worldMax[a] > box.worldMin[a])) {
            throw ValueError("--dense-box " + formatValue(box.worldMin[a]) + ".." + formatValue(box.worldMax[a]) + " along " + "xyz"[a] +
                             ": each max must be above its min (X0,Y0,Z0,X1,Y1,Z1)");
        }
    }
    if (p.denseSize.size() != 3 || *std::min_element(p.denseSize.begin(), p.denseSize.end()) < 1 ||
        double(p.denseSize[0]) * p.denseSize[1] * p.denseSize[2] > double(1 << 28)) {
        throw ValueError("--dense-size: must be D,H,W (samples along z, y, x), each at least 1, at most 2^28 samples in all");
    }
    box.size = openvdb::Coord(p.denseSize[2], p.denseSize[1], p.denseSize[0]);
    return box;
}

int runField(const FieldCmdParams& p, const CommonOptions& common)
{
    if (p.output.empty()) throw ValueError("needs an output: -o OUT.vdb");
    if (fileExtension(p.output) != ".vdb") throw ValueError(p.output + ": the field is written as OpenVDB; the output must end in .vdb");
    checkParamOptions(fieldLevelsParameters(), p.params);
    const int levels = p.params.levels;
    const std::string space = fieldSpaceName(p.params.field.space);
    if (p.helicoid && levels != 1) throw ValueError("--helicoid with --levels " + std::to_string(levels) + ": a helicoid field has one level; use --levels 1");
    if (p.helicoid && space != "world") throw ValueError("--helicoid with --space " + space + ": helicoid fields are world-space");
    if (p.vectorName.empty() || p.vectorName.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_") != std::string::npos ||
        std::isdigit(static_cast<unsigned char>(p.vectorName[0]))) {
        throw ValueError("--vector-name '" + p.vectorName + "': must be a valid attribute name (letters, digits, _; not starting with a digit)");
    }
    if (!p.dense.empty() && fileExtension(p.dense) != ".npy") throw ValueError("--dense " + p.dense + ": the orientation volume is written as NumPy; it must end in .npy");
    if (!p.dense.empty() && space != "world") throw ValueError("--dense with --space " + space + ": the dense box is in world space; use --space world");
    if (p.dense.empty() && !p.denseBox.empty()) throw ValueError("--dense-box without --dense: name the .npy to write (--dense OUT.npy)");
    const DenseBox denseBox = p.dense.empty() ? DenseBox{} : denseBoxOption(p);
    if (p.helicoid && p.vectorName != "tangent") throw ValueError("--helicoid with --vector-name " + p.vectorName + ": retrace --helicoid reads the vector grid 'tangent'");

    const StrandSet strands = loadStrands("field", p.input, common);
    checkStrandLengths("field", p.input, strands, common);
    FieldParams fp = p.params.field;
    fp.voxelSize = resolveVoxelSize(strands, fp);  // 0: the library's suggestion (reported below)
    fp.coherenceAndSpread = false;  // not written (below)
    applyScalpOptions(p.scalp, strands, fp, common);

    const auto t0 = std::chrono::steady_clock::now();
    const std::vector<TangentField> fields = estimateTangentFieldLevels(strands, fp, levels, true, common.interrupter);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

    openvdb::GridCPtrVec grids;  // the voxel grids (the report's), then the strands
    for (const TangentField& f : fields) {
        if (p.vectorName != "tangent") {  // e.g. hair_direction: Blender's Cycles reserves 'tangent'
            const std::string name = f.tangent->getName();
            f.tangent->setName(p.vectorName + name.substr(std::string("tangent").size()));
        }
        for (const openvdb::GridBase::Ptr& g : {openvdb::GridBase::Ptr(f.tangent), openvdb::GridBase::Ptr(f.density), openvdb::GridBase::Ptr(f.hairLength)}) {
            g->insertMeta("vdbhair_source", openvdb::StringMetadata(p.input));
            grids.push_back(g);
        }
    }
    if (p.helicoid) {
        const HelicoidFieldGrids h = estimateHelicoidField(strands, *fields[0].tangent, true, common.interrupter);
        for (const openvdb::GridBase::Ptr& g : {openvdb::GridBase::Ptr(h.k), openvdb::GridBase::Ptr(h.alpha),
                                                openvdb::GridBase::Ptr(h.frameT), openvdb::GridBase::Ptr(h.frameN)}) {
            grids.push_back(g);
        }
    }
    nlohmann::json j = fieldReport(strands.numStrands(), fp, levels, grids);
    if (p.withStrands) grids.push_back(createStrandGrid(strands));
    std::vector<float> volume;
    if (!p.dense.empty()) {
        const Stage stage(common, "resampling the orientation volume");
        volume = orientationVolume(*fields[0].tangent, denseBox);
    }
    {
        const Stage stage(common, "writing " + p.output);
        writeVdbGrids(p.output, grids, "field(" + p.output + ")");
        if (!p.dense.empty()) writeNpy(p.dense, {std::size_t(p.denseSize[0]), std::size_t(p.denseSize[1]), std::size_t(p.denseSize[2]), 4}, volume.data());
    }

    if (common.json) {
        j["output"] = p.output;
        j["seconds"] = seconds;
        if (!p.dense.empty()) {
            j["dense"] = denseReport(denseBox, volume);
            j["dense"]["output"] = p.dense;
        }
        if (fp.space == FieldSpace::Scalp && fp.scalpSurface) j["scalp"]["surface"] = p.scalp.scalp;
        printJson(j);
    } else if (!common.quiet) {
        std::cout << "field of " << strands.numStrands() << " strands, voxel size " << fp.voxelSize << " ("
                  << fieldSpaceName(fp.space) << " space), " << fp.iterations << " iteration(s), " << levels << " level(s):\n";
        for (const auto& g : j["grids"]) {
            std::cout << "  " << g["name"].get<std::string>() << ": " << g["active_voxels"].get<std::uint64_t>()
                      << " active voxels of size " << g["voxel_size"].get<double>() << "\n";
        }
        std::cout << "wrote " << p.output << "\n";
        if (!p.dense.empty()) std::cout << "wrote " << p.dense << ": orientation volume " << p.denseSize[0] << " x " << p.denseSize[1] << " x " << p.denseSize[2] << " x 4\n";
    }
    return 0;
}

} // namespace

Command addFieldCommand(CLI::App& app, CommonOptions& common)
{
    auto params = std::make_shared<FieldCmdParams>();
    CLI::App* sub = addVerb(app, "field");
    sub->add_option("input", params->input, "Strand file")->required();
    sub->add_option("-o,--output", params->output, "Output .vdb: grids 'tangent', 'density' (fog volume in [0,1]) and 'hair_length' (or *_level_<l>)")->required();
    addParamOptions(sub, params->params, fieldLevelsParameters());
    sub->add_option("--vector-name", params->vectorName,
                    "Name of the direction grid; Blender's Cycles reserves 'tangent' for UV tangents, so use e.g. hair_direction for Cycles")
        ->capture_default_str();
    sub->add_flag("--helicoid", params->helicoid, "Also fit a helicoid per voxel: grids helicoid_k, helicoid_alpha, frame_T, frame_N");
    sub->add_flag("--with-strands", params->withStrands, "Also write the strands as the points grid 'strands'");
    addStrictOption(sub, common);
    sub->add_option("--dense", params->dense,
                    "Also write the orientation volume as NumPy .npy: float32 (D, H, W, 4), [k][j][i] = sample (i, j, k) along (x, y, z), "
                    "channels tx, ty, tz (unit, root to tip; 0 outside the hair) and occupancy (the active voxels' mask, trilinear, in [0,1]); "
                    "from level 0 (the finest); world space only");
    sub->add_option("--dense-box", params->denseBox, "The world box of --dense: X0,Y0,Z0,X1,Y1,Z1; samples at the centres of its D x H x W cells")
        ->delimiter(',')->expected(6);
    const auto& shape = kDefaultDenseShape;
    sub->add_option("--dense-size", params->denseSize,
                    "Samples of --dense: D,H,W (along z, y, x; NeuralHDHair's " + std::to_string(shape[0]) + "," + std::to_string(shape[1]) + "," +
                        std::to_string(shape[2]) + " by default)")
        ->delimiter(',')->expected(3);
    addScalpOptions(sub, params->scalp);
    addCommonOptions(sub, common);
    addReadOptions(sub, common);
    sub->footer("Example: vdbhair field hair.hair -o field.vdb --voxel-size 0.5 --levels 3\n"
                "Orientation volume: vdbhair field hair.data -o f.vdb --dense f.npy --dense-box -0.32,-0.32,-0.24,0.32,0.32,0.24");
    return {sub, [params, &common] { return runField(*params, common); }};
}

} // namespace vdbhair::app
