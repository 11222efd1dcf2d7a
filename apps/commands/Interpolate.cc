// vdbhair interpolate GUIDES -o OUT (--roots ROOTS | --scalp scalp.vdb --count N): new hairs from
// guide hairs, by interpolating their helicoid parameters (Piuze et al. 2011, §4) or, as the
// peers do, their points (--method points).
#include "../Command.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/helicoid/HelicoidFit.h>
#include <vdbhair/helicoid/HelicoidInterpolation.h>
#include <vdbhair/helicoid/PointInterpolation.h>
#include <vdbhair/helicoid/Scene.h>
#include <vdbhair/io/FileUtil.h>
#include <vdbhair/io/PointFile.h>
#include <vdbhair/io/StrandIO.h>
#include <vdbhair/io/VdbFile.h>
#include <vdbhair/scalp/Follicles.h>

#include <chrono>
#include <cmath>

namespace vdbhair::app {

namespace {

struct InterpolateCmdParams
{
    std::string guides, output, roots, scalp, method = "helicoid", frames = "auto";
    std::string up = axisName(HelicoidInterpolationParams{}.up);
    std::string blend = helicoidBlendName(HelicoidInterpolationParams{}.blend);
    std::int64_t count = -1;  ///< -1: not given
    std::uint64_t seed = 0;
    HelicoidInterpolationParams helicoid;
    PointInterpolationParams points;
    int neighbors = 0;  ///< 0: not given (each method's own default)
    CLI::Option* neighborsOpt = nullptr;
};

Vec3d toD(const Vec3f& v) { return Vec3d(v.x(), v.y(), v.z()); }

/// The guides as a scene: read, or fitted to a strand file on the fly.
Scene loadGuides(const std::string& path, const CommonOptions& common, double& fitSeconds)
{
    if (fileExtension(path) == ".json") return readScene(path);
    const StrandSet strands = loadStrands("interpolate", path, common);
    const auto t0 = std::chrono::steady_clock::now();
    Scene scene = guideSceneFromStrands(strands, FitParams{}, path, true, common.interrupter);
    fitSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return scene;
}

int runInterpolate(InterpolateCmdParams p, const CommonOptions& common)
{
    // Arguments first, before any work.
    const bool points = p.method == "points";
    if (p.method != "helicoid" && !points) throw ValueError("--method '" + p.method + "' is not one of helicoid, points");
    if (p.frames != "auto" && p.frames != "world" && p.frames != "surface") throw ValueError("--frames '" + p.frames + "' is not one of auto, world, surface");
    const bool sceneOut = fileExtension(p.output) == ".json";
    if (sceneOut && points) throw ValueError(p.output + ": --method points makes strands, not helicoids; write a strand format or use --method helicoid");
    if (!sceneOut) strandFormatFromPath(p.output, /*forWriting=*/true);
    if (p.roots.empty() == p.scalp.empty()) throw ValueError("needs --roots ROOTS or --scalp SCALP.vdb --count N (one of them)");
    if (!p.scalp.empty() && p.count < 0) throw ValueError("--scalp needs --count N");
    if (p.count == 0) throw ValueError("--count 0: must be at least 1");
    p.helicoid.blend = helicoidBlendFromName(p.blend);
    if (!(p.helicoid.shepard.power > 0.0) || !std::isfinite(p.helicoid.shepard.power)) {
        throw ValueError("--power " + formatValue(p.helicoid.shepard.power) + ": must be a positive finite exponent (the paper uses 3)");
    }
    if (p.neighborsOpt && p.neighborsOpt->count() > 0) {
        if (p.neighbors < 1) throw ValueError("--neighbors " + std::to_string(p.neighbors) + ": must be at least 1 (omit it to use " + (points ? std::to_string(PointInterpolationParams{}.neighbors) : std::string("every guide")) + ")");
        p.helicoid.shepard.neighbors = p.neighbors;
        p.points.neighbors = p.neighbors;
    }
    p.helicoid.up = axisFromName(p.up, "--up");

    double fitSeconds = 0.0;
    const Scene guides = loadGuides(p.guides, common, fitSeconds);
    if (guides.guides.empty()) throw ValueError(p.guides + ": no guides: interpolation needs at least one");
    validateGuideScene(guides);
    const HelicoidInterpolator probe(guides, p.helicoid);  // checks the guides; bounds a hair's vertices
    auto checkCount = [&](double count) {
        const double estimate = count * double(probe.maxVerticesPerHair());
        if (estimate > double(p.helicoid.maxVertices)) {
            throw LimitError(formatValue(count) + " strands would grow up to " + formatValue(estimate) + " vertices, more than the cap of " +
                             std::to_string(p.helicoid.maxVertices) + " (--max-vertices; 12 bytes a vertex): ask for fewer strands");
        }
    };

    // Roots: a root file (PLY points with optional normals, or the roots of any strand file), or follicles on a scalp.
    InterpolationRoots roots;
    if (!p.roots.empty()) {
        if (fileExtension(p.roots) == ".ply" && plyElementCount(p.roots, "vertex") > 0) {
            const Stage stage(common, "reading " + p.roots);
            const OrientedPoints op = readPlyPoints(p.roots);
            checkCount(double(op.size()));
            for (const Vec3f& v : op.positions) roots.positions.push_back(toD(v));
            for (const Vec3f& v : op.normals) roots.normals.push_back(toD(v));
        } else {
            const StrandSet s = loadStrands("interpolate", p.roots, common);
            checkCount(double(s.numStrands()));
            for (std::size_t i = 0; i < s.numStrands(); ++i) roots.positions.push_back(toD(s.root(i)));
        }
        if (roots.positions.empty()) throw ValueError(p.roots + ": no roots");
    } else {
        checkCount(double(p.count));
        openvdb::GridBase::Ptr g = readVdbGrid(p.scalp, "surface", "interpolate(" + p.scalp + ")");
        openvdb::FloatGrid::Ptr surface = openvdb::GridBase::grid<openvdb::FloatGrid>(g);
        if (!surface || surface->getGridClass() != openvdb::GRID_LEVEL_SET) throw TypeError(p.scalp + ": grid 'surface' is not a float level set; vdbhair scalp makes one");
        openvdb::BoolGrid::Ptr region;
        const std::vector<std::string> names = vdbGridNames(p.scalp, p.scalp);
        if (std::find(names.begin(), names.end(), "region") != names.end()) {
            region = openvdb::GridBase::grid<openvdb::BoolGrid>(readVdbGrid(p.scalp, "region", p.scalp));
        }
        FollicleParams fp;
        fp.count = std::size_t(p.count);
        fp.seed = p.seed;
        fp.up = p.helicoid.up;
        const Follicles f = sampleFollicles(surface, region, fp, true, common.interrupter);
        for (const Vec3f& v : f.positions) roots.positions.push_back(toD(v));
        for (const Vec3f& v : f.normals) roots.normals.push_back(toD(v));
    }
    if (p.frames == "world") roots.normals.clear();
    if (p.frames == "surface" && roots.normals.empty()) {
        throw ValueError((p.roots.empty() ? p.scalp : p.roots) + ": the roots have no normals (PLY nx ny nz); --frames surface needs them");
    }
    // Guide normals: radial on the scene's head sphere, else those of the nearest roots (the library's rule).
    std::vector<Vec3d> guideNormals;
    if (!roots.normals.empty()) guideNormals = sceneGuideNormals(guides);

    const auto t0 = std::chrono::steady_clock::now();
    StrandSet strands;
    Scene out;
    if (points) {
        // The guides' own strands (no wisps), blended point by point.
        strands = interpolatePoints(guides, roots, p.points, guideNormals, true, common.interrupter);
    } else {
        out = interpolateHelicoids(guides, roots, p.helicoid, guideNormals, true, common.interrupter);
        out.seed = p.seed;
        if (!sceneOut) {
            GrowOptions grow;
            grow.maxVertices = p.helicoid.maxVertices;
            strands = growScene(out, grow, true, common.interrupter);
        }
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    {
        const Stage stage(common, "writing " + p.output);
        if (sceneOut) writeScene(p.output, out);
        else writeStrands(p.output, strands);
    }
    const std::size_t count = roots.positions.size();
    if (common.json) {
        printJson({{"output", p.output}, {"method", p.method}, {"blend", points ? nlohmann::json(nullptr) : nlohmann::json(p.blend)},
                   {"guides", guides.guides.size()}, {"strands", count},
                   {"vertices", sceneOut ? nlohmann::json(nullptr) : nlohmann::json(strands.numVertices())},
                   {"frames", roots.normals.empty() ? "world" : "surface"}, {"seconds", seconds},
                   {"strands_per_second", double(count) / seconds}, {"fit_seconds", fitSeconds}});
    } else if (!common.quiet) {
        std::cout << "interpolated " << count << " strands from " << guides.guides.size() << " guides (" << p.method << ", "
                  << (roots.normals.empty() ? "world" : "surface") << " frames) in " << seconds << " s (" << double(count) / seconds
                  << " strands/s)\nwrote " << p.output << "\n";
    }
    return 0;
}

} // namespace

Command addInterpolateCommand(CLI::App& app, CommonOptions& common)
{
    auto params = std::make_shared<InterpolateCmdParams>();
    CLI::App* sub = addVerb(app, "interpolate");
    sub->add_option("guides", params->guides, "Guides: a helicoid scene (.json, e.g. from vdbhair fit) or any strand file (fitted first)")->required();
    sub->add_option("-o,--output", params->output, "Output: any strand format, or a scene (.json, --method helicoid)")->required();
    sub->add_option("--roots", params->roots, "Roots: PLY points (x y z, optional nx ny nz, as vdbhair roots writes) or the roots of any strand file");
    sub->add_option("--scalp", params->scalp, "Scalp .vdb (vdbhair scalp): spread --count roots over it (and its region)");
    sub->add_option("--count", params->count, "Number of roots on --scalp");
    sub->add_option("--method", params->method, "helicoid (Piuze et al.) or points (Blender's Interpolate Curves)")->capture_default_str();
    sub->add_option("--blend", params->blend, "helicoid: arcs (each guide re-described as equal circular arcs in its rotation-minimizing frame, "
                                              "so guides blend alike) or fitted (the fits' own pieces, as the paper prints it)")->capture_default_str();
    sub->add_option("--arcs", params->helicoid.arcs, "--blend arcs: arcs per hair (0: one per 0.2 radian of the most-turning guide, 16 to 512)")->capture_default_str();
    sub->add_option("--power", params->helicoid.shepard.power, "Shepard exponent p: weights |x - x_i|^-p")->capture_default_str();
    params->neighborsOpt = sub->add_option("--neighbors", params->neighbors, "Guides per new hair, nearest by root (default: every guide for helicoid, " +
                                           std::to_string(PointInterpolationParams{}.neighbors) + " for points)");
    sub->add_option("--frames", params->frames, "auto (surface when the roots have normals), world, or surface (the scalp's frame, 4.3)")->capture_default_str();
    sub->add_option("--up", params->up, "Reference axis of surface frames: x, y, z, -x, -y or -z")->capture_default_str();
    sub->add_option("--seed", params->seed, "Seed of the roots on --scalp and of waviness noise")->capture_default_str();
    sub->add_option("--max-vertices", params->helicoid.maxVertices, "Refuse requests that would make more vertices (12 bytes each)")->capture_default_str();
    addCommonOptions(sub, common);
    sub->footer("Example: vdbhair interpolate guides.json --roots roots.ply -o hair.hair --json");
    return {sub, [params, &common] {
                params->points.maxVertices = params->helicoid.maxVertices;
                return runInterpolate(*params, common);
            },
            {{"blend", "--blend"}}};
}

} // namespace vdbhair::app
