// vdbhair demo [SCENE] -o DIR: the README's main job on the bundled default hairstyle.
#include "../Command.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/io/StrandIO.h>
#include <vdbhair/strands/Measures.h>

#include <filesystem>

namespace vdbhair::app {

namespace {

struct DemoParams
{
    std::string scene;
    std::string outDir = "vdbhair-demo";
};

int runDemo(const DemoParams& p, const CommonOptions& common)
{
    namespace fs = std::filesystem;
    ReadReport report;
    const StrandSet strands = readStrands(p.scene, {}, &report);
    printWarnings("demo", report, common);
    if (strands.empty()) throw FormatError(p.scene + ": the scene has no strands");
    std::error_code ec;
    fs::create_directories(p.outDir, ec);
    if (ec) throw IoError(p.outDir + ": cannot create the output folder: " + ec.message());

    const StrandSummary s = summarizeStrands(strands);
    const std::string vdbPath = (fs::path(p.outDir) / "strands.vdb").string();
    writeStrands(vdbPath, strands);
    if (common.json) {
        printJson({{"scene", p.scene}, {"strands", s.strands}, {"vertices", s.vertices},
                   {"length", {{"min", s.length.min}, {"mean", s.length.mean}, {"max", s.length.max}}},
                   {"outputs", {vdbPath}}});
    } else {
        std::cout << "scene " << p.scene << ": " << s.strands << " strands, " << s.vertices << " vertices, "
                  << "length " << s.length.min << " .. " << s.length.max << " (mean " << s.length.mean << ")\n"
                  << "wrote " << vdbPath << " (OpenVDB points grid 'strands'; open it in Houdini or Blender)\n";
    }
    return 0;
}

} // namespace

Command addDemoCommand(CLI::App& app, CommonOptions& common)
{
    auto params = std::make_shared<DemoParams>();
    CLI::App* sub = app.add_subcommand("demo", "Run the main job on a hairstyle and write every result into one folder");
    sub->add_option("scene", params->scene, "The hairstyle (the README passes the bundled default)")->required();
    sub->add_option("-o,--output", params->outDir, "Output folder (created if missing)")->capture_default_str();
    addCommonOptions(sub, common);
    return {sub, [params, &common] { return runDemo(*params, common); }};
}

} // namespace vdbhair::app
