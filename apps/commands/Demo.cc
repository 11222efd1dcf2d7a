// vdbhair demo SCENE -o DIR: the README's main job: refine the bundled hairstyle through its own
// tangent field and write the strands, the field and the report into one folder.
#include "../AppParameters.h"
#include "../ParamOptions.h"
#include "../RefineOptions.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/helicoid/Scene.h>
#include <vdbhair/io/FileUtil.h>
#include <vdbhair/io/StrandIO.h>
#include <vdbhair/io/VdbFile.h>
#include <vdbhair/io/VdbStrandGrid.h>
#include <vdbhair/render/StrandRenderer.h>
#include <vdbhair/strands/Measures.h>

#include <chrono>
#include <filesystem>

namespace vdbhair::app {

namespace {

struct DemoParams
{
    std::string outDir = "vdbhair-demo";
    RefineCmdParams refine;
};

int runDemo(const DemoParams& p, const CommonOptions& common)
{
    namespace fs = std::filesystem;
    // The declared ranges and the library's rules across parameters, before the scene is read.
    checkParamOptions(demoParameters(), p.refine.refine);
    p.refine.refine.validate("option");
    const auto t0 = std::chrono::steady_clock::now();
    TriangleMesh head;  // a scene's own head, drawn in the preview
    const StrandSet strands = loadStrandsOrScene("demo", p.refine.input, common, "strands", &head);
    RefineParams rp = refineParamsFrom(p.refine, strands, common);
    // A scene's own head is the obstacle refinement keeps strands out of, unless --head says otherwise.
    if (p.refine.head.path.empty() && fileExtension(p.refine.input) == ".json") {
        const Scene scene = readScene(p.refine.input);
        if (scene.head) rp.head = HeadObstacle::sphere(scene.head->center, scene.head->radius, p.refine.head.headPolicy());
    }
    rp.measure = true;  // the demo's report is what an artist checks the refinement by
    std::error_code ec;
    fs::create_directories(p.outDir, ec);
    if (ec) throw IoError(p.outDir + ": cannot create the output folder: " + ec.message());

    const RefineResult r = refineStrands(strands, rp, true, common.interrupter);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

    const std::string dir = p.outDir;
    const std::string refinedPath = (fs::path(dir) / "refined.hair").string();
    const std::string fieldPath = (fs::path(dir) / "field.vdb").string();
    const std::string strandsPath = (fs::path(dir) / "strands.vdb").string();
    const std::string reportPath = (fs::path(dir) / "report.json").string();
    const std::string previewPath = (fs::path(dir) / "preview.png").string();
    // Before (top row) and after (bottom row): front, side and three-quarter views, one framing.
    RenderParams view;
    view.width = 480;
    view.height = 480;
    view.interrupter = common.interrupter;
    BBox box = computeBBox(strands);
    const BBox refinedBox = computeBBox(r.strands);
    box.expand(refinedBox.min);
    box.expand(refinedBox.max);
    if (!head.triangles.empty()) {
        view.head = &head;
        box.expand(meshBBox(head).min);
        box.expand(meshBBox(head).max);
    }
    view.frame = box;
    Image sheet(3 * view.width, 2 * view.height, view.background);
    const View views[3] = {View::Front, View::Side, View::ThreeQuarter};
    for (int row = 0; row < 2; ++row) {
        for (int i = 0; i < 3; ++i) {
            view.view = views[i];
            view.title = std::string(row == 0 ? "input" : "refined") + ": " + viewName(views[i]);
            sheet.paste(renderStrands(row == 0 ? strands : r.strands, view), i * view.width, row * view.height);
        }
    }
    // Everything is computed before the first file is written, so that Ctrl-C during the work
    // leaves the folder as it was.
    {
        const Stage writing(common, "writing " + dir);
        writeStrands(refinedPath, r.strands);
        writeVdbGrids(fieldPath, fieldGrids(r, p.refine.input), "demo(" + fieldPath + ")");
        {
            // The input and refined strands as points grids, for side-by-side viewing in Houdini/Blender.
            auto before = createStrandGrid(strands);
            before->setName("strands_input");
            auto after = createStrandGrid(r.strands);
            writeVdbGrids(strandsPath, {after, before}, "demo(" + strandsPath + ")");
        }
        writeImage(previewPath, sheet);
    }
    const StrandSummary s = summarizeStrands(strands);
    nlohmann::json report = refineReport(r, rp);
    report["scene"] = p.refine.input;
    report["vertices"] = s.vertices;
    report["seconds"] = seconds;
    report["outputs"] = {refinedPath, fieldPath, strandsPath, previewPath, reportPath};
    writeFileAtomic(reportPath, report.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n", "demo(" + reportPath + ")");

    if (common.json) {
        printJson(report);
    } else {
        std::cout << "scene " << p.refine.input << ": " << s.strands << " strands, " << s.vertices << " vertices, length "
                  << s.length.min << " .. " << s.length.max << " (mean " << s.length.mean << ")\n"
                  << "refined through its own tangent field (" << rp.levels << " level(s), finest voxel size " << r.voxelSize
                  << ", " << rp.field.iterations << " iterations of Wang et al. Eq. 9) in " << seconds << " s\n";
        printRefineReport(r, rp);
        std::cout << "wrote " << refinedPath << " (refined strands)\n"
                  << "wrote " << fieldPath << " (grids 'tangent', 'density', 'hair_length', 'coherence' and 'spread')\n"
                  << "wrote " << strandsPath << " (points grids 'strands' and 'strands_input', for Houdini or Blender)\n"
                  << "wrote " << previewPath << " (before and after)\n"
                  << "wrote " << reportPath << "\n";
    }
    return 0;
}

} // namespace

Command addDemoCommand(CLI::App& app, CommonOptions& common)
{
    auto params = std::make_shared<DemoParams>();
    CLI::App* sub = addVerb(app, "demo");
    sub->add_option("scene", params->refine.input, "The hairstyle: strands, or a helicoid scene .json (the README passes the bundled default)")->required();
    sub->add_option("-o,--output", params->outDir, "Output folder (created if missing)")->capture_default_str();
    addRefineOptions(sub, params->refine, demoSkippedParameters());  // demoParameters(): the demo always measures
    addStrictOption(sub, common);
    addCommonOptions(sub, common);
    addReadOptions(sub, common);
    sub->footer("Example: vdbhair demo scenes/default/head.json -o out --levels 2");
    return {sub, [params, &common] { return runDemo(*params, common); }};
}

} // namespace vdbhair::app
