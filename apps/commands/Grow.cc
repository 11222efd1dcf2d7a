// vdbhair grow SCENE.json -o OUT: helicoid scenes (Piuze et al. 2011) to strands.
#include "../Command.h"
#include "../ParamOptions.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/helicoid/HelicoidJson.h>
#include <vdbhair/helicoid/Scene.h>
#include <vdbhair/io/StrandIO.h>
#include <vdbhair/strands/Measures.h>

#include <chrono>
#include <cstdio>

namespace vdbhair::app {

namespace {

struct GrowParams
{
    std::string scene, output;
    GrowOptions grow;  ///< its declared parameters (growParameters()) are options
};

int runGrow(const GrowParams& p, const CommonOptions& common)
{
    strandFormatFromPath(p.output, /*forWriting=*/true);
    checkParamOptions(growParameters(), p.grow);
    const GrowOptions& opts = p.grow;
    const Scene scene = readScene(p.scene);
    const auto t0 = std::chrono::steady_clock::now();
    GrowReport report;
    const StrandSet strands = growScene(scene, opts, true, common.interrupter, &report);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (strands.empty()) throw FormatError(p.scene + ": the scene has no guides; nothing to write");
    {
        const Stage stage(common, "writing " + p.output);
        writeStrands(p.output, strands);
    }
    if (report.nearAxis && !common.quiet) {
        char nearest[32];
        std::snprintf(nearest, sizeof nearest, "%.2g", report.nearestClearance);
        std::cerr << "vdbhair grow: warning: " << report.nearAxis << " of " << scene.guides.size() << " guides pass within "
                  << formatValue(opts.nearAxisSteps) << " step of a piece's singular axis (guide " << report.nearestGuide << ": " << nearest
                  << " steps), where a trace depends on the step: their strands change with a smaller 'step' (refit them, or grow at a finer step to see)\n";
    }
    if (common.json) {
        nlohmann::json j = growReport(scene, strands, report);
        j["scene"] = p.scene;
        j["output"] = p.output;
        j["seconds"] = seconds;
        printJson(j);
    } else if (!common.quiet) {
        std::cout << "grew " << strands.numStrands() << " strands (" << scene.guides.size() << " guides and their wisps), "
                  << strands.numVertices() << " vertices in " << seconds << " s\nwrote " << p.output << "\n";
    }
    return 0;
}

} // namespace

Command addGrowCommand(CLI::App& app, CommonOptions& common)
{
    auto params = std::make_shared<GrowParams>();
    CLI::App* sub = addVerb(app, "grow");
    sub->add_option("scene", params->scene, "Scene file (JSON, \"vdbhair\": \"scene/1\")")->required();
    sub->add_option("-o,--output", params->output, "Output strand file (.hair .data .obj .ply .vdb .usda)")->required();
    addParamOptions(sub, params->grow, growParameters());
    addCommonOptions(sub, common);
    sub->footer("Example: vdbhair grow scenes/figures/fig3_wisp.json -o wisp.hair");
    return {sub, [params, &common] { return runGrow(*params, common); }};
}

} // namespace vdbhair::app
