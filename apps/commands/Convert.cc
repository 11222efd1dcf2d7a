// vdbhair convert IN [IN...] OUT: strands from any readable format to any writable one.
#include "../Command.h"
#include "../ParamOptions.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/io/ConvertStrands.h>
#include <vdbhair/io/StrandIO.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>

#include <unistd.h>

namespace vdbhair::app {

namespace {

/// The command line of convert: its declared parameters (convertParameters()), then its own.
struct ConvertCmdParams
{
    std::vector<std::string> files;
    std::string output;
    ConvertParams convert;  ///< its declared parameters are options
    std::vector<double> rootNear;  ///< x, y, z; empty: OBJ roots at the lower-index end
    std::string format;  ///< the format of `-` (standard input or output), e.g. "obj"
    std::string units;       ///< convert to this unit (mm, cm, m, ... or metres); empty: keep
    std::string inputUnits;  ///< the inputs' unit, declared or overriding the files'; empty: theirs
};

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

int runConvert(ConvertCmdParams p, const CommonOptions& common)
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
    strandFormatFromPath(p.output, /*forWriting=*/true);
    for (const std::string& in : inputs) if (in != "-") strandFormatFromPath(in);
    for (std::string& in : inputs) {
        if (in != "-") continue;
        in = stdio.make("stdin", ext);
        std::ofstream f(in, std::ios::binary);
        f << std::cin.rdbuf();
        if (!f) throw IoError("cannot copy standard input to " + in);
    }
    checkParamOptions(convertParameters(), p.convert);
    p.convert.validate();
    const WriteOptions& wopts = p.convert.write;
    const double metersPerUnit = wopts.usd.metersPerUnit;
    ReadOptions ropts = readOptions(common);
    if (!p.rootNear.empty()) {
        if (p.rootNear.size() != 3) throw ValueError("--root-near needs X,Y,Z");
        ropts.objRootNear = Vec3f(float(p.rootNear[0]), float(p.rootNear[1]), float(p.rootNear[2]));
    }
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
        if (metersPerUnit > 0.0 && metersPerUnit != target) {
            throw ValueError("--units " + p.units + " and --meters-per-unit " + formatValue(metersPerUnit) + " disagree; give one");
        }
        if (!(strands.metersPerUnit > 0.0)) {
            throw ValueError("--units " + p.units + ": " + (inputs.size() == 1 ? inputs[0] : std::string("the inputs")) +
                             " declare(s) no unit to convert from; give it with --input-units (e.g. --input-units cm)");
        }
        convertUnits(strands, target);
    }
    if (!common.quiet && !(strands.metersPerUnit > 0.0) && metersPerUnit == 0.0 && strandFormatFromPath(p.output, true) == StrandFormat::Usda) {
        std::cerr << "vdbhair convert: warning: " << p.output << ": the input declares no unit; the stage says metersPerUnit = 0.01 "
                     "(centimetres, USD's fallback): give the input's unit with --input-units UNIT if it is not centimetres\n";
    }
    {
        const Stage stage(common, p.convert.resample >= 2 ? "resampling" : "converting");
        convertStrands(strands, p.convert);
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
    auto params = std::make_shared<ConvertCmdParams>();
    CLI::App* sub = addVerb(app, "convert");
    sub->add_option("files", params->files, "IN [IN...] OUT, or IN [IN...] with -o OUT")->required();
    sub->add_option("-o,--output", params->output, "Output file; its extension picks the format (.hair .data .obj .ply .vdb .usda)");
    addParamOptions(sub, params->convert, convertParameters());
    addStrictOption(sub, common);
    sub->add_option("--root-near", params->rootNear,
                    "OBJ input: root each strand at its end nearest X,Y,Z (e.g. the head's centre) instead of its lower-index end")
        ->delimiter(',')->expected(3);
    sub->add_option("--units", params->units,
                    "Convert to this unit (mm, cm, dm, m, in, or its length in metres): positions and thickness scaled from the input's "
                    "declared unit (a USD stage's metersPerUnit, or --input-units), which outputs with a unit (USD) then declare");
    sub->add_option("--input-units", params->inputUnits,
                    "The inputs' unit (mm, cm, dm, m, in, or metres), for files that declare none or declare it wrongly; nothing is scaled by it");
    sub->add_option("--format", params->format, "The format of '-' (standard input or output): hair, data, obj, ply, vdb or usda");
    addParamOptions(sub, common.read, selectParams(readParameters(), {"grid"}));
    addCommonOptions(sub, common);
    addReadOptions(sub, common);
    sub->footer("Example: vdbhair convert hair.tfx hair.vdb --resample 32");
    return {sub, [params, &common] { return runConvert(*params, common); }};
}

} // namespace vdbhair::app
