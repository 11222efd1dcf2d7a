// vdbhair roots scalp.vdb -o roots.ply: follicles spread over a scalp level set (Witkin &
// Heckbert 1994 repulsion on the zero level set), in its region when it has one.
#include "../Command.h"
#include "../ParamOptions.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/io/FileUtil.h>
#include <vdbhair/io/PointFile.h>
#include <vdbhair/io/VdbFile.h>
#include <vdbhair/scalp/Follicles.h>
#include <vdbhair/scalp/RootGrid.h>
#include <vdbhair/scalp/ScalpInput.h>
#include <vdbhair/scalp/ScalpJson.h>

#include <algorithm>
#include <chrono>
#include <cmath>

namespace vdbhair::app {

namespace {

struct RootsCmdParams
{
    std::string input, output;
    FollicleParams follicle;  ///< its declared parameters (follicleParameters()) are options
    bool noRegion = false;
};

int runRoots(const RootsCmdParams& p, const CommonOptions& common)
{
    const std::string ext = fileExtension(p.output);
    if (ext != ".ply" && ext != ".vdb") throw ValueError(p.output + ": roots are written as .ply (x y z nx ny nz tx ty tz) or .vdb (points); the output must end in one of them");
    checkParamOptions(follicleParameters(), p.follicle);
    FollicleParams fp = p.follicle;
    if (fp.count == 0 && fp.spacing == 0.0) throw ValueError("needs --count N or --spacing S");
    if (fp.count > 0 && fp.spacing > 0.0) throw ValueError("--count and --spacing: give one");

    openvdb::FloatGrid::Ptr surface;
    openvdb::BoolGrid::Ptr region;
    {
        const Stage stage(common, "reading " + p.input);
        surface = readScalp(p.input, common.interrupter);
        if (!p.noRegion) region = readScalpRegion(p.input);
    }
    const auto t0 = std::chrono::steady_clock::now();
    const Follicles f = sampleFollicles(surface, region, fp, true, common.interrupter);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const FollicleStats stats = measureFollicles(f.positions, surface);
    warnBandWithoutZero("roots", p.input, f.area, f.areaWithoutZero, common);

    OrientedPoints out;
    out.positions = f.positions;
    out.normals = f.normals;
    out.tangents = f.tangents;
    {
        const Stage stage(common, "writing " + p.output);
        if (ext == ".ply") writePlyPoints(p.output, out);
        else writeVdbGrids(p.output, {createRootGrid(out)}, "roots(" + p.output + ")");
    }
    if (common.json) {
        nlohmann::json j = rootsReport(f, stats, bool(region));
        j["output"] = p.output;
        j["seconds"] = seconds;
        printJson(j);
    } else if (!common.quiet) {
        std::cout << "roots: " << f.positions.size() << " on " << (region ? "the region" : "the surface") << " (area " << formatValue(f.area)
                  << "), target spacing " << formatValue(f.targetSpacing) << ", " << f.iterations << " iterations in " << seconds << " s\n"
                  << (f.contour > 0 ? std::to_string(f.contour) + " fixed on the region's rim; " : std::string()) << f.fissions << " fissions, " << f.deaths << " deaths\n"
                  << "nearest-neighbour spacing: mean " << stats.nnMean << ", coefficient of variation " << stats.nnCV
                  << "; largest distance from the surface " << stats.maxSurfaceDistanceVoxels << " voxels\n"
                  << "wrote " << p.output << "\n";
    }
    return 0;
}

} // namespace

Command addRootsCommand(CLI::App& app, CommonOptions& common)
{
    auto params = std::make_shared<RootsCmdParams>();
    CLI::App* sub = addVerb(app, "roots");
    sub->add_option("scalp", params->input, "Scalp .vdb with grid 'surface' (and 'region'), as vdbhair scalp writes; or a head mesh (.ply, .obj), made into one at 1/100 of its size")->required();
    sub->add_option("-o,--output", params->output, "Output roots: .ply (x y z nx ny nz tx ty tz) or .vdb (points P, N, tangent, group root)")->required();
    addParamOptions(sub, params->follicle, follicleParameters());
    sub->add_flag("--no-region", params->noRegion, "Ignore the file's 'region' grid: roots over the whole surface");
    addCommonOptions(sub, common);
    sub->footer("Example: vdbhair roots scalp.vdb -o roots.ply --count 10000 --json");
    return {sub, [params, &common] { return runRoots(*params, common); }};
}

} // namespace vdbhair::app
