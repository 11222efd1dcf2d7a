// vdbhair render IN -o OUT.png: preview images of strands (any strand format, .vdb points, or a scene).
#include "../Command.h"
#include "../ParamOptions.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/io/FileUtil.h>
#include <vdbhair/io/MeshFile.h>
#include <vdbhair/io/PointFile.h>
#include <vdbhair/render/StrandRenderer.h>

#include <chrono>

namespace vdbhair::app {

namespace {

/// The command line of render; defaults from the library's RenderParams and ReadOptions.
struct RenderCmdParams
{
    std::string input, output, guides, head, reference;
    RenderParams render;  ///< its declared parameters (renderParameters()) are options
};

int runRender(const RenderCmdParams& p, const CommonOptions& common)
{
    checkParamOptions(renderParameters(), p.render);
    RenderParams rp = p.render;
    rp.interrupter = common.interrupter;
    if (rp.facing && std::abs(rp.facing->dot(rp.up)) > 0.5) {
        throw ValueError("--facing " + axisName(*rp.facing) + " with --up " + axisName(rp.up) + ": the face must look along an axis perpendicular to up");
    }
    if (!isImagePath(p.output)) throw ValueError(p.output + ": not an image format OpenImageIO writes (use .png, .exr or .jpg)");
    // Roots (a PLY of points with normals, as `vdbhair roots` writes) are drawn as dots: stubs
    // along their normals, 1/60 of the roots' extent long.
    const bool rootsInput = fileExtension(p.input) == ".ply" && plyElementCount(p.input, "strand") == 0 &&
                            plyElementCount(p.input, "face") == 0;
    StrandSet strands;
    TriangleMesh head;  // --head, or the scene's own head
    if (rootsInput) {
        const OrientedPoints roots = readPlyPoints(p.input);
        if (roots.size() == 0) throw FormatError(p.input + ": the file has no points");
        if (roots.normals.size() != roots.size()) throw FormatError(p.input + ": the points have no normals (nx ny nz); render draws roots along them");
        BBox box;
        for (const Vec3f& q : roots.positions) box.expand(q);
        const float len = box.extent().length() / 60.f;
        for (std::size_t i = 0; i < roots.size(); ++i) {
            strands.addStrand(std::vector<Vec3f>{roots.positions[i], roots.positions[i] + roots.normals[i] * len});
        }
    } else {
        strands = loadStrandsOrScene("render", p.input, common, common.read.vdbGrid, p.head.empty() ? &head : nullptr);
    }
    StrandSet guides;
    if (!p.guides.empty()) {
        guides = loadStrandsOrScene("render", p.guides, common);
        rp.guides = &guides;
    }
    if (!p.head.empty()) {
        const Stage stage(common, "reading " + p.head);
        head = readTriangleMesh(p.head);
    }
    if (!head.triangles.empty()) rp.head = &head;
    StrandSet reference;
    if (rp.colorBy == ColorBy::Error && p.reference.empty()) {
        throw ValueError("--color-by error: needs --reference, the hairstyle to measure each vertex's distance to");
    }
    if (!p.reference.empty()) {
        if (rp.colorBy != ColorBy::Error) throw ValueError("--reference " + p.reference + ": only --color-by error uses it");
        reference = loadStrandsOrScene("render", p.reference, common, common.read.vdbGrid);
        rp.reference = &reference;
    }
    const auto t0 = std::chrono::steady_clock::now();
    const Image image = rp.sheet ? renderSheet(strands, rp) : renderStrands(strands, rp);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    writeImage(p.output, image);
    if (common.json) {
        printJson({{"output", p.output}, {"width", image.width}, {"height", image.height}, {"strands", strands.numStrands()},
                   {"view", rp.sheet ? "sheet" : viewName(rp.view)}, {"seconds", seconds}});
    } else if (!common.quiet) {
        std::cout << "rendered " << strands.numStrands() << (rootsInput ? " roots (" : " strands (") << (rp.sheet ? std::string("sheet") : std::string(viewName(rp.view))) << ", "
                  << image.width << "x" << image.height << ") in " << seconds << " s\nwrote " << p.output << "\n";
    }
    return 0;
}

} // namespace

Command addRenderCommand(CLI::App& app, CommonOptions& common)
{
    auto params = std::make_shared<RenderCmdParams>();
    CLI::App* sub = addVerb(app, "render");
    sub->add_option("input", params->input, "Strands (any format), .vdb points, a scene .json, or roots (.ply points with normals: drawn as dots)")->required();
    sub->add_option("-o,--output", params->output, "Image (.png, .exr, .jpg: by extension)")->required();
    addParamOptions(sub, params->render, renderParameters());
    sub->add_option("--reference", params->reference, "For --color-by error: the hairstyle to measure against (e.g. the reference of `compare`)");
    sub->add_option("--head", params->head, "A head mesh (.ply, .obj) drawn behind the hair, e.g. from ../shared/data/scalp (default: a scene's own \"head\")");
    sub->add_option("--guides", params->guides, "Strands drawn on top in red (e.g. the guides of a scene)");
    addParamOptions(sub, common.read, selectParams(readParameters(), {"grid"}));
    addCommonOptions(sub, common);
    addReadOptions(sub, common);
    sub->footer("Example: vdbhair render scenes/default/head.json -o head.png --sheet");
    return {sub, [params, &common] { return runRender(*params, common); }};
}

} // namespace vdbhair::app
