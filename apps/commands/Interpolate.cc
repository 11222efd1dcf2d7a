// vdbhair interpolate GUIDES -o OUT (--roots ROOTS | --scalp scalp.vdb --count N): new hairs from
// guide hairs, by blending the guides' points by group and likeness (the default) or their helicoid
// parameters (Piuze et al. 2011, §4), kept out of the head (vdbhair/helicoid/GuideInterpolation.h).
#include "../Command.h"
#include "../ParamOptions.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/field/Refine.h>
#include <vdbhair/helicoid/GuideInterpolation.h>
#include <vdbhair/helicoid/HelicoidJson.h>
#include <vdbhair/helicoid/Scene.h>
#include <vdbhair/io/FileUtil.h>
#include <vdbhair/io/PointFile.h>
#include <vdbhair/io/StrandIO.h>
#include <vdbhair/io/VdbFile.h>
#include <vdbhair/scalp/Follicles.h>
#include <vdbhair/scalp/HeadFile.h>
#include <vdbhair/scalp/RootValues.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <tuple>

namespace vdbhair::app {

namespace {

struct InterpolateCmdParams
{
    std::string guides, output, roots, scalp, head, guideGroups, rootGroups, density, length;
    InterpolateParams op;  ///< its declared parameters (interpolateParameters()) are options
    std::int64_t count = -1;  ///< -1: not given
};

Vec3d toD(const Vec3f& v) { return Vec3d(v.x(), v.y(), v.z()); }

/// The options into @a p.op, checked before any work (the library checks them again, in its own words).
void checkOptions(InterpolateCmdParams& p)
{
    InterpolateParams& op = p.op;
    checkParamOptions(interpolateParameters(), op);
    const bool points = op.method == InterpolationMethod::Points;
    op.returnScene = fileExtension(p.output) == ".json";
    if (op.returnScene && points) throw ValueError(p.output + ": --method points makes strands, not helicoids; write a strand format or use --method helicoid");
    if (!op.returnScene) strandFormatFromPath(p.output, /*forWriting=*/true);
    if (p.roots.empty() == p.scalp.empty()) throw ValueError("needs --roots ROOTS or --scalp SCALP.vdb --count N (one of them)");
    if (!p.scalp.empty() && p.count < 0) throw ValueError("--scalp needs --count N");
    if (p.count == 0) throw ValueError("--count 0: must be at least 1");
    if (!points && (!p.guideGroups.empty() || !p.rootGroups.empty())) throw ValueError("--guide-groups and --root-groups need --method points");
    validateGroomParams(op.groom);  // what the ranges do not say: curl needs a frequency
    if (op.returnScene && (groomsHair(op.groom) || !p.density.empty() || !p.length.empty())) {
        throw ValueError(p.output + ": a scene of new hairs takes no --density, --length, --clump-radius, --curl or --frizz; write strands");
    }
}

/// The guides as read: a scene, or strands (blended as they are, or fitted for helicoids).
/// `guides` points into the other two members, so the whole is filled in place and never copied.
struct GuideInput
{
    Scene scene;
    StrandSet strands;
    InterpolationGuides guides;

    GuideInput() = default;
    GuideInput(const GuideInput&) = delete;
    GuideInput& operator=(const GuideInput&) = delete;

    std::size_t count() const { return guides.scene ? scene.guides.size() : strands.numStrands(); }
};

/// Read the guides (and --guide-groups, one id per guide root) into @a in.
void readGuides(const InterpolateCmdParams& p, const CommonOptions& common, GuideInput& in)
{
    in.guides.where = p.guides;
    if (fileExtension(p.guides) == ".json") {
        in.scene = readScene(p.guides);
        if (in.scene.guides.empty()) throw ValueError(p.guides + ": no guides: interpolation needs at least one");
        validateGuideScene(in.scene);
        in.guides.scene = &in.scene;
    } else {
        in.strands = loadStrands("interpolate", p.guides, common);
        if (in.strands.empty()) throw ValueError(p.guides + ": no guides: interpolation needs at least one");
        in.guides.strands = &in.strands;
    }
    const std::size_t G = in.count();
    if (!p.guideGroups.empty()) {
        std::vector<Vec3d> guideRoots(G);
        for (std::size_t i = 0; i < G; ++i) guideRoots[i] = in.guides.scene ? in.scene.guides[i].root : toD(in.strands.root(i));
        in.guides.groups = readRootIds(p.guideGroups, guideRoots, "--guide-groups", "guides");
    }
}

/// A bound of the vertices a new hair has, for the cap before the roots are made.
std::size_t verticesPerHairBound(const GuideInput& in, const InterpolateParams& op)
{
    std::size_t perHair = 0;
    if (in.guides.scene) {
        const HelicoidInterpolator probe(in.scene, op.helicoid);  // checks the guides; bounds a hair's vertices
        perHair = probe.maxVerticesPerHair();
    } else {
        // The guides' own counts: exact for points; for helicoids a first bound (fits are traced at
        // their own step), which interpolateHelicoids() checks exactly before growing anything.
        for (std::size_t i = 0; i < in.count(); ++i) perHair = std::max(perHair, in.strands.size(i));
    }
    return perHair;
}

/// @throw LimitError when @a count new hairs of up to @a perHair vertices could pass --max-vertices.
void checkStrandCount(double count, std::size_t perHair, const InterpolateParams& op)
{
    const double estimate = count * double(perHair);
    if (estimate > double(op.helicoid.maxVertices)) {
        throw LimitError(formatValue(count) + " strands would grow up to " + formatValue(estimate) + " vertices, more than the cap of " +
                         std::to_string(op.helicoid.maxVertices) + " (--max-vertices; 12 bytes a vertex): ask for fewer strands");
    }
}

/// --roots: PLY points with optional normals, or the roots of any strand file.
InterpolationRoots readRootsFile(const InterpolateCmdParams& p, const CommonOptions& common, std::size_t perHair)
{
    InterpolationRoots roots;
    if (fileExtension(p.roots) == ".ply" && plyElementCount(p.roots, "vertex") > 0) {
        const Stage stage(common, "reading " + p.roots);
        const OrientedPoints pts = readPlyPoints(p.roots);
        checkStrandCount(double(pts.size()), perHair, p.op);
        for (const Vec3f& v : pts.positions) roots.positions.push_back(toD(v));
        for (const Vec3f& v : pts.normals) roots.normals.push_back(toD(v));
    } else {
        const StrandSet s = loadStrands("interpolate", p.roots, common);
        checkStrandCount(double(s.numStrands()), perHair, p.op);
        for (std::size_t i = 0; i < s.numStrands(); ++i) roots.positions.push_back(toD(s.root(i)));
    }
    if (roots.positions.empty()) throw ValueError(p.roots + ": no roots");
    return roots;
}

/// --scalp with --count: follicles spread over the scalp's surface (in its region, if it has one);
/// the surface becomes @a head.
InterpolationRoots rootsOnScalp(const InterpolateCmdParams& p, const CommonOptions& common, std::size_t perHair, HeadObstacle& head)
{
    checkStrandCount(double(p.count), perHair, p.op);
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
    fp.seed = p.op.seed;
    fp.up = p.op.helicoid.up;
    const Follicles f = sampleFollicles(surface, region, fp, true, common.interrupter);
    InterpolationRoots roots;
    for (const Vec3f& v : f.positions) roots.positions.push_back(toD(v));
    for (const Vec3f& v : f.normals) roots.normals.push_back(toD(v));
    head = HeadObstacle::levelSet(surface);
    head.setLabel("--scalp " + p.scalp);
    return roots;
}

/// The per-root controls: --root-groups, and density and length per root (a number, a mask grid,
/// a painted mesh property, or a list: RootValues.h); then the normals --frames surface needs.
void readRootControls(const InterpolateCmdParams& p, InterpolationRoots& roots)
{
    if (!p.rootGroups.empty()) roots.groups = readRootIds(p.rootGroups, roots.positions, "--root-groups", "roots");
    for (auto [spec, values, option, grid] : {std::tuple{&p.density, &roots.density, "--density", "density"}, std::tuple{&p.length, &roots.length, "--length", "length"}}) {
        if (spec->empty()) continue;
        *values = readRootValues(*spec, roots.positions, option, grid);
        const bool any = std::any_of(values->begin(), values->end(), [](float v) { return v > 0.f; });
        if (!any) throw ValueError(std::string(option) + " " + *spec + ": 0 at every one of the " + std::to_string(values->size()) + " roots: no hair would grow (a mask that covers none of them?)");
    }
    if (p.op.frames == FrameRule::Surface && roots.normals.empty()) {
        throw ValueError((p.roots.empty() ? p.scalp : p.roots) + ": the roots have no normals (PLY nx ny nz); --frames surface needs them");
    }
}

/// The head: --head, else --scalp's surface (@a scalpHead, empty without --scalp), else the
/// scene's sphere, else a sphere fitted to the guide roots.
HeadObstacle chooseHead(const InterpolateCmdParams& p, const GuideInput& in, HeadObstacle scalpHead)
{
    if (p.head == "none") return HeadObstacle::none();
    if (!p.head.empty()) return readHeadObstacle(p.head, "--head " + p.head);
    if (!scalpHead.empty()) return scalpHead;
    if (in.guides.scene && in.scene.head) return HeadObstacle::sphere(in.scene.head->center, in.scene.head->radius);
    if (in.guides.strands) return headFromRoots(in.strands, p.op.helicoid.up);
    return scalpHead;
}

void writeOutput(const InterpolateCmdParams& p, const CommonOptions& common, const GuideInput& in, const InterpolateResult& r)
{
    const Stage stage(common, "writing " + p.output);
    if (p.op.returnScene) {
        writeScene(p.output, r.scene);
    } else if (fileExtension(p.output) == ".abc" && p.op.method == InterpolationMethod::Points) {
        // Unreal's groom: the guides beside the new hair, each strand bound to its guides.
        writeGroomAbc(p.output, in.guides.scene ? growGuides(in.scene, true, common.interrupter) : in.strands, in.guides.groups, r);
    } else {
        writeStrands(p.output, r.strands);
    }
}

/// The new hairs made: strands, or a scene's helicoids.
std::size_t newHairCount(const InterpolateResult& r) { return r.strands.numStrands() > 0 ? r.strands.numStrands() : r.scene.guides.size(); }

void reportJson(const InterpolateCmdParams& p, const HeadObstacle& head, const InterpolateResult& r)
{
    nlohmann::json j = interpolateReport(r, p.op, head);
    j["output"] = p.output;
    j["seconds"] = r.seconds;
    j["strands_per_second"] = double(newHairCount(r)) / r.seconds;
    printJson(j);
}

void reportText(const InterpolateCmdParams& p, const HeadObstacle& head, const InterpolateResult& r)
{
    const InterpolateParams& op = p.op;
    const std::size_t count = newHairCount(r);
    std::cout << "interpolated " << count << " strands from " << r.guides << " guides (" << interpolationMethodName(op.method) << ", "
              << frameRuleName(op.frames) << " frames";
    if (op.method == InterpolationMethod::Points) {
        std::cout << ", " << r.groups << (r.groups == 1 ? " group" : " groups") << ", grouping " << guideGroupingName(op.points.grouping);
    }
    char seconds[32];
    std::snprintf(seconds, sizeof seconds, "%.3f", r.seconds);
    std::cout << ") in " << seconds << " s\n";
    if (r.rootsDropped > 0 || r.cut > 0) {
        std::cout << "density and length: " << r.rootsDropped << " of " << r.roots << " roots left bare, " << r.cut << " hairs cut shorter\n";
    }
    if (r.groom.clumps > 0) std::cout << "clumps: " << r.groom.clumps << " centres, " << r.groom.clumped << " hairs pulled in\n";
    if (r.groom.curled > 0) std::cout << "curl: " << r.groom.curled << " hairs (" << r.groom.addedVertices << " vertices added for " << int(kCurlVerticesPerTurn) << " a turn)\n";
    if (!head.empty() && !op.returnScene) {
        const double enteringShare = double(r.enteringHead) / double(count);
        const double guidesEnteringShare = double(r.guidesEnteringHead) / double(std::max<std::size_t>(1, r.guides));
        char shares[96];
        std::snprintf(shares, sizeof shares, "%.1f %% of the new strands, %.1f %% of the guides", 100.0 * enteringShare, 100.0 * guidesEnteringShare);
        std::cout << "head: " << head.describe(false) << " (no new vertex deeper than its root); " << r.pushedOut << " strands pushed out";
        if (r.groom.curled > 0 || r.groom.clumped > 0 || op.groom.curl.frizz > 0.0) std::cout << " (and " << r.groomPushedOut << " touched up after curl, clumps and frizz)";
        std::cout << "; passing into it: " << shares << "\n";
    }
    if (!op.returnScene) {
        char share[64];
        std::snprintf(share, sizeof share, "%.1f %%", 100.0 * double(r.leavingVolume) / double(std::max<std::size_t>(1, r.volumeSample)));
        std::cout << "leaving the guides' hair volume (voxel " << formatValue(r.volumeVoxel) << ", dilated by one): " << share << " of the new strands";
        if (r.volumeSample < count) std::cout << " (measured on " << r.volumeSample << " spread over them)";
        std::cout << "\n";
    }
    std::cout << "wrote " << p.output << "\n";
}

int runInterpolate(InterpolateCmdParams p, const CommonOptions& common)
{
    checkOptions(p);  // before any work
    GuideInput in;
    readGuides(p, common, in);
    const std::size_t perHair = verticesPerHairBound(in, p.op);
    HeadObstacle scalpHead;
    InterpolationRoots roots = p.roots.empty() ? rootsOnScalp(p, common, perHair, scalpHead) : readRootsFile(p, common, perHair);
    readRootControls(p, roots);
    const HeadObstacle head = chooseHead(p, in, std::move(scalpHead));

    const InterpolateResult r = interpolateGuides(in.guides, roots, head, p.op, true, common.interrupter);
    writeOutput(p, common, in, r);
    if (common.json) reportJson(p, head, r);
    else if (!common.quiet) reportText(p, head, r);
    return 0;
}

} // namespace

Command addInterpolateCommand(CLI::App& app, CommonOptions& common)
{
    auto params = std::make_shared<InterpolateCmdParams>();
    InterpolateCmdParams& p = *params;
    CLI::App* sub = addVerb(app, "interpolate");
    sub->add_option("guides", p.guides, "Guides: any strand file, or a helicoid scene (.json, e.g. from vdbhair fit)")->required();
    sub->add_option("-o,--output", p.output, "Output: any strand format, or a scene (.json, --method helicoid)")->required();
    sub->add_option("--roots", p.roots, "Roots: PLY points (x y z, optional nx ny nz, as vdbhair roots writes) or the roots of any strand file");
    sub->add_option("--scalp", p.scalp, "Scalp .vdb (vdbhair scalp): spread --count roots over it (and its region); it is also the head");
    sub->add_option("--count", p.count, "Number of roots on --scalp");
    sub->add_option("--guide-groups", p.guideGroups, "points: group ids of the guides, new hairs blending only guides of one group: a text file of one integer "
                                                      "per guide, MASK.vdb[:GRID] (the voxel at each guide root; grid 'groups'), MESH.ply:PROPERTY (the nearest vertex's), "
                                                      "or MESH.ply|obj:islands (the mesh's connected pieces: a scalp cut along its partings)");
    sub->add_option("--root-groups", p.rootGroups, "points: group ids of the roots, as --guide-groups (default: the group of the nearest guide)");
    sub->add_option("--density", p.density, "Share of the roots that grow hair, in [0, 1]: a number, MASK.vdb[:GRID] (a float or bool grid; "
                                            "default grid 'density'), MESH.ply:PROPERTY (painted on the head's vertices), or a text file of one value per root");
    sub->add_option("--length", p.length, "Share of each new hair's length kept, in [0, 1] (0 grows none): as --density (default grid 'length')");
    sub->add_option("--head", p.head, "The head new hair may not enter deeper than its guides: a mesh (.ply, .obj), a .vdb level set, or 'none' "
                                      "(default: --scalp's surface, else the scene's head, else a sphere fitted to the guide roots)");
    addParamOptions(sub, p.op, interpolateParameters());
    addCommonOptions(sub, common);
    addReadOptions(sub, common);
    sub->footer("Example: vdbhair interpolate guides.hair --scalp scalp.vdb --count 20000 -o hair.hair --json");
    return {sub, [params, &common] { return runInterpolate(*params, common); }};
}

} // namespace vdbhair::app
