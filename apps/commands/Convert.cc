// vdbhair convert IN [IN...] OUT: strands from any readable format to any writable one.
#include "../Command.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/io/StrandIO.h>
#include <vdbhair/strands/Measures.h>
#include <vdbhair/strands/Resample.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>

#include <unistd.h>

namespace vdbhair::app {

namespace {

struct ConvertParams
{
    std::vector<std::string> files;
    std::string output;
    std::size_t resample = 0;  ///< vertices per strand; 0 keeps them
    double scale = 1.0;
    std::string plyEncoding = "binary";
    std::string codec = positionCodecName(WriteOptions{}.vdb.codec);
    double voxelSize = 0.0;
    bool strict = false;
    std::string objLines = "edges";
    std::vector<double> rootNear;  ///< x, y, z; empty: OBJ roots at the lower-index end
    std::string grid = ReadOptions{}.vdbGrid;
    std::string usdUp;  ///< empty: the input's declared up axis, else y
    double metersPerUnit = WriteOptions{}.usd.metersPerUnit;
    float width = WriteOptions{}.usd.width;
    std::string format;  ///< the format of `-` (standard input or output), e.g. "obj"
    std::string up = "y";  ///< the input's up axis; rotated onto +Y
    std::string units;       ///< convert to this unit (mm, cm, m, ... or metres); empty: keep
    std::string inputUnits;  ///< the inputs' unit, declared or overriding the files'; empty: theirs
};

/// @brief Rotate @a strands so that the axis @a up (a unit axis, possibly negative) becomes +Y,
/// by a quarter or half turn that keeps the frame right-handed.
void rotateUpToY(StrandSet& strands, const Vec3d& up)
{
    auto map = [&](const Vec3f& p) -> Vec3f {
        if (up.z() > 0.5) return Vec3f(p.x(), p.z(), -p.y());   // -90 deg about X
        if (up.z() < -0.5) return Vec3f(p.x(), -p.z(), p.y());  // +90 deg about X
        if (up.x() > 0.5) return Vec3f(-p.y(), p.x(), p.z());   // +90 deg about Z
        if (up.x() < -0.5) return Vec3f(p.y(), -p.x(), p.z());  // -90 deg about Z
        if (up.y() < -0.5) return Vec3f(p.x(), -p.y(), -p.z()); // 180 deg about X
        return p;
    };
    if (up.y() > 0.5) return;
    for (Vec3f& p : strands.positions) p = map(p);
    strands.upAxis = 'Y';
}

/// Files standing in for `-`: standard input copied into one, standard output written from one.
/// Removed when the command ends.
struct StdioFiles
{
    std::vector<std::string> paths;
    ~StdioFiles()
    {
        std::error_code ec;
        for (const std::string& f : paths) std::filesystem::remove(f, ec);
    }
    std::string make(const std::string& role, const std::string& ext)
    {
        static int counter = 0;
        const std::string name = "vdbhair-" + role + "-" + std::to_string(::getpid()) + "-" + std::to_string(counter++) + ext;
        paths.push_back((std::filesystem::temp_directory_path() / name).string());
        return paths.back();
    }
};

int runConvert(ConvertParams p, const CommonOptions& common)
{
    // Inputs and output: `convert IN OUT`, `convert IN... -o OUT`.
    std::vector<std::string> inputs = p.files;
    if (p.output.empty()) {
        if (inputs.size() < 2) throw ValueError("needs an output: 'convert IN OUT' or 'convert IN -o OUT'");
        p.output = inputs.back();
        inputs.pop_back();
    }
    // `-`: standard input or output, in the format --format names.
    StdioFiles stdio;
    std::string ext = p.format.empty() ? std::string() : (p.format[0] == '.' ? p.format : "." + p.format);
    for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
    const bool toStdout = p.output == "-";
    const std::size_t fromStdin = std::size_t(std::count(inputs.begin(), inputs.end(), std::string("-")));
    if ((toStdout || fromStdin) && ext.empty()) throw ValueError("'-' (standard input or output) needs --format, e.g. --format obj");
    if (fromStdin > 1) throw ValueError("'-' (standard input) can be read once");
    if (toStdout && common.json) throw ValueError("--json with output '-': standard output carries the strands");
    if (toStdout) p.output = stdio.make("stdout", ext);
    if (fromStdin) strandFormatFromPath("stdin" + ext);
    // Check everything about the command line before reading anything.
    WriteOptions wopts;
    strandFormatFromPath(p.output, /*forWriting=*/true);
    for (const std::string& in : inputs) if (in != "-") strandFormatFromPath(in);
    for (std::string& in : inputs) {
        if (in != "-") continue;
        in = stdio.make("stdin", ext);
        std::ofstream f(in, std::ios::binary);
        f << std::cin.rdbuf();
        if (!f) throw IoError("cannot copy standard input to " + in);
    }
    if (p.resample == 1) throw ValueError("--resample 1: a strand needs at least 2 vertices");
    if (!std::isfinite(p.scale) || p.scale == 0.0) throw ValueError("--scale " + formatValue(p.scale) + ": must be finite and non-zero");
    if (p.plyEncoding == "ascii") wopts.plyEncoding = PlyEncoding::Ascii;
    else if (p.plyEncoding != "binary") throw ValueError("--ply-encoding '" + p.plyEncoding + "': must be ascii or binary");
    wopts.vdb.codec = positionCodecFromName(p.codec);
    if (p.voxelSize < 0.0 || !std::isfinite(p.voxelSize)) throw ValueError("--voxel-size " + formatValue(p.voxelSize) + ": must be a positive length (0 chooses it)");
    wopts.vdb.voxelSize = p.voxelSize;
    wopts.objLines = objLineStyleFromName(p.objLines);
    axisFromName(p.up, "--up");
    if (!p.usdUp.empty() && p.usdUp != "y" && p.usdUp != "z" && p.usdUp != "Y" && p.usdUp != "Z") throw ValueError("--usd-up '" + p.usdUp + "': must be y or z (USD's choices)");
    wopts.usd.upAxis = p.usdUp.empty() ? "" : p.usdUp == "z" || p.usdUp == "Z" ? "Z" : "Y";
    if (!(p.metersPerUnit >= 0.0) || !std::isfinite(p.metersPerUnit)) throw ValueError("--meters-per-unit " + formatValue(p.metersPerUnit) + ": must be a positive length (0: the input's own, else 0.01)");
    wopts.usd.metersPerUnit = p.metersPerUnit;
    if (!(p.width >= 0.f) || !std::isfinite(p.width)) throw ValueError("--width " + formatValue(p.width) + ": must be a positive length in world units (0: automatic)");
    wopts.usd.width = p.width;

    ReadOptions ropts = readOptions(common);
    ropts.vdbGrid = p.grid;
    if (!p.rootNear.empty()) {
        if (p.rootNear.size() != 3) throw ValueError("--root-near needs X,Y,Z");
        ropts.objRootNear = Vec3f(float(p.rootNear[0]), float(p.rootNear[1]), float(p.rootNear[2]));
    }
    if (p.strict) ropts.shortStrands = ShortStrandPolicy::Reject;
    StrandSet strands;
    ReadReport report;
    for (const std::string& in : inputs) {
        const Stage stage(common, "reading " + in);
        strands.append(readStrands(in, ropts, &report));
    }
    printWarnings("convert", report, common);
    if (strands.empty()) {
        std::string what = inputs.size() == 1 ? inputs[0] + ": the file has no strands" : "the " + std::to_string(inputs.size()) + " inputs have no strands";
        throw FormatError(what + "; nothing to write to " + p.output);
    }
    // Units: declared (--input-units) and converted (--units) only when asked.
    if (!p.inputUnits.empty()) {
        const double declared = metersPerUnitFromName(p.inputUnits, "--input-units");
        if (strands.metersPerUnit > 0.0 && strands.metersPerUnit != declared && !common.quiet) {
            std::cerr << "vdbhair convert: warning: the input declares " << formatValue(strands.metersPerUnit) << " m per unit; --input-units "
                      << p.inputUnits << " overrides it (nothing is scaled by that)\n";
        }
        strands.metersPerUnit = declared;
    }
    if (!p.units.empty()) {
        const double target = metersPerUnitFromName(p.units, "--units");
        if (p.metersPerUnit > 0.0 && p.metersPerUnit != target) {
            throw ValueError("--units " + p.units + " and --meters-per-unit " + formatValue(p.metersPerUnit) + " disagree; give one");
        }
        if (!(strands.metersPerUnit > 0.0)) {
            throw ValueError("--units " + p.units + ": " + (inputs.size() == 1 ? inputs[0] : std::string("the inputs")) +
                             " declare(s) no unit to convert from; give it with --input-units (e.g. --input-units cm)");
        }
        convertUnits(strands, target);
    }
    if (!common.quiet && !(strands.metersPerUnit > 0.0) && p.metersPerUnit == 0.0 && strandFormatFromPath(p.output, true) == StrandFormat::Usda) {
        std::cerr << "vdbhair convert: warning: " << p.output << ": the input declares no unit; the stage says metersPerUnit = 0.01 "
                     "(centimetres, USD's fallback): give the input's unit with --input-units UNIT if it is not centimetres\n";
    }
    if (p.scale != 1.0) scaleStrands(strands, float(p.scale));
    rotateUpToY(strands, axisFromName(p.up, "--up"));
    if (p.resample >= 2) {
        const Stage stage(common, "resampling");
        strands = resampleStrands(strands, p.resample);
    }
    {
        const Stage stage(common, "writing " + (toStdout ? std::string("standard output") : p.output));
        writeStrands(p.output, strands, wopts);
    }
    if (toStdout) {
        std::ifstream f(p.output, std::ios::binary);
        std::cout << f.rdbuf();
        std::cout.flush();
        if (!std::cout) throw IoError("cannot write the strands to standard output");
        if (!common.quiet) std::cerr << "vdbhair convert: wrote " << strands.numStrands() << " strands, " << strands.numVertices() << " vertices to standard output\n";
        return 0;
    }

    if (common.json) {
        printJson({{"inputs", inputs}, {"output", p.output}, {"strands", strands.numStrands()},
                   {"vertices", strands.numVertices()}, {"dropped_strands", report.droppedStrands}});
    } else if (!common.quiet) {
        std::cout << "wrote " << p.output << ": " << strands.numStrands() << " strands, "
                  << strands.numVertices() << " vertices\n";
    }
    return 0;
}

} // namespace

Command addConvertCommand(CLI::App& app, CommonOptions& common)
{
    auto params = std::make_shared<ConvertParams>();
    CLI::App* sub = addVerb(app, "convert");
    sub->add_option("files", params->files, "IN [IN...] OUT, or IN [IN...] with -o OUT")->required();
    sub->add_option("-o,--output", params->output, "Output file; its extension picks the format (.hair .data .obj .ply .vdb .usda)");
    sub->add_option("--resample", params->resample, "Resample every strand to N vertices, equally spaced in arc length")->check(CLI::NonNegativeNumber);
    sub->add_option("--scale", params->scale, "Multiply every position (and thickness) by S");
    sub->add_option("--ply-encoding", params->plyEncoding, "PLY output encoding: binary (little-endian) or ascii")->capture_default_str();
    sub->add_option("--codec", params->codec, "VDB position codec: float (exact), fixed16, fixed8")->capture_default_str();
    sub->add_option("--voxel-size", params->voxelSize, "VDB points voxel size in world units (default: about 8 points per voxel)");
    sub->add_flag("--strict", params->strict, "Reject strands of fewer than 2 vertices instead of dropping them");
    sub->add_option("--obj-lines", params->objLines,
                    "OBJ output: edges (a two-vertex 'l' per segment, what Blender's importer reads whole) or polylines (one 'l' per strand, Houdini)")
        ->capture_default_str();
    sub->add_option("--root-near", params->rootNear,
                    "OBJ input: root each strand at its end nearest X,Y,Z (e.g. the head's centre) instead of its lower-index end")
        ->delimiter(',')->expected(3);
    sub->add_option("--usd-up", params->usdUp, "USD output: the stage's upAxis, y or z (coordinates are not rotated; default: the input's declared axis, else y)");
    sub->add_option("--meters-per-unit", params->metersPerUnit,
                    "USD output: the stage's metersPerUnit (0: the input's own, from a USD stage, else 0.01: centimetres); nothing is scaled")
        ->capture_default_str();
    sub->add_option("--units", params->units,
                    "Convert to this unit (mm, cm, dm, m, in, or its length in metres): positions and thickness scaled from the input's "
                    "declared unit (a USD stage's metersPerUnit, or --input-units), which outputs with a unit (USD) then declare");
    sub->add_option("--input-units", params->inputUnits,
                    "The inputs' unit (mm, cm, dm, m, in, or metres), for files that declare none or declare it wrongly; nothing is scaled by it");
    sub->add_option("--width", params->width,
                    "USD output: the widths (world units) of strands without thickness (default: the file's own default thickness, else 1/1000 of the bounding box's diagonal)");
    sub->add_option("--up", params->up,
                    "The input's up axis (x, y, z, -x, -y, -z), turned onto +Y, vdbhair's and OBJ's convention (cyHair models: z)")
        ->capture_default_str();
    sub->add_option("--format", params->format, "The format of '-' (standard input or output): hair, data, obj, ply, vdb or usda");
    sub->add_option("--grid", params->grid, "VDB input: the points grid holding the strands (e.g. strands_input)")->capture_default_str();
    addCommonOptions(sub, common);
    addReadOptions(sub, common);
    sub->footer("Example: vdbhair convert hair.tfx hair.vdb --resample 32");
    return {sub, [params, &common] { return runConvert(*params, common); }};
}

} // namespace vdbhair::app
