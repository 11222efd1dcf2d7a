#include "GuideInterpolation.h"

#include <vdbhair/io/AbcFile.h>

#include <vdbhair/Exceptions.h>
#include <vdbhair/field/HairVolume.h>
#include <vdbhair/field/HeadCollision.h>
#include <vdbhair/field/TangentField.h>
#include <vdbhair/strands/Compare.h>
#include <vdbhair/strands/Measures.h>

#include <algorithm>
#include <chrono>
#include <cmath>

namespace vdbhair {

bool groomsHair(const GroomParams& groom)
{
    return groom.clump.radius > 0.0 || groom.curl.amplitude > 0.0 || groom.curl.frizz > 0.0;
}

namespace {

double secondsSince(std::chrono::steady_clock::time_point t0)
{
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// The arguments, before any work: the guides given one way, the method's options, the roots'
/// per-root arrays one per root.
void checkArguments(const InterpolationGuides& guides, const InterpolationRoots& rootsIn, const InterpolateParams& params)
{
    if ((guides.strands == nullptr) == (guides.scene == nullptr)) throw ValueError("interpolateGuides: give the guides as strands or as a scene (one of them)");
    const bool points = params.method == InterpolationMethod::Points;
    if (params.returnScene && points) throw ValueError("a scene of new hairs needs the helicoid method (points make strands)");
    if (!points && !guides.groups.empty()) throw ValueError("guide groups need the points method; helicoid interpolation blends every guide");
    if (params.frames == FrameRule::Surface && rootsIn.normals.empty()) throw ValueError("surface frames need root normals; the roots have none");
    if (rootsIn.positions.empty()) throw ValueError("no roots: interpolation needs at least one root");
    if (params.returnScene && (groomsHair(params.groom) || !rootsIn.density.empty() || !rootsIn.length.empty())) {
        throw ValueError("a scene of new hairs takes no groom controls (density, length, clumps, curl, frizz): grow it first");
    }
    validateGroomParams(params.groom);
    const std::size_t R0 = rootsIn.positions.size();
    if (!rootsIn.normals.empty() && rootsIn.normals.size() != R0) {
        throw ValueError(std::to_string(rootsIn.normals.size()) + " root normals for " + std::to_string(R0) + " roots: one per root");
    }
    if (!rootsIn.groups.empty() && rootsIn.groups.size() != R0) {
        throw ValueError(std::to_string(rootsIn.groups.size()) + " root group ids for " + std::to_string(R0) + " roots: one per root");
    }
}

/// The roots that grow hair: density (and a length of 0) leave roots bare before any hair is
/// made. World frames need no normals.
InterpolationRoots keptRoots(const InterpolationRoots& rootsIn, const InterpolateParams& params)
{
    const std::size_t R0 = rootsIn.positions.size();
    const std::vector<char> keep = rootsKept(R0, rootsIn.density, rootsIn.length, params.seed);
    InterpolationRoots roots;
    for (std::size_t i = 0; i < R0; ++i) {
        if (!keep[i]) continue;
        roots.positions.push_back(rootsIn.positions[i]);
        if (!rootsIn.normals.empty()) roots.normals.push_back(rootsIn.normals[i]);
        if (!rootsIn.groups.empty()) roots.groups.push_back(rootsIn.groups[i]);
        if (!rootsIn.length.empty()) roots.length.push_back(rootsIn.length[i]);
    }
    if (roots.positions.empty()) throw ValueError("the density and length leave none of the " + std::to_string(R0) + " roots to grow hair: no hair would be made");
    if (params.frames == FrameRule::World) roots.normals.clear();
    return roots;
}

/// The points method: the guides' own points (a scene's guides grown, without wisps, into
/// @a grownGuides), blended by interpolatePoints(). Returns the guides as strands.
const StrandSet* interpolateByPoints(const InterpolationGuides& guides, const InterpolationRoots& roots, const HeadObstacle& head,
                                     const InterpolateParams& params, bool threaded, openvdb::util::NullInterrupter* interrupter,
                                     InterpolateResult& res, std::vector<std::uint32_t>& rootGroups, StrandSet& grownGuides)
{
    const StrandSet* guidePoints = guides.strands;
    if (guides.scene) {
        validateGuideScene(*guides.scene);
        grownGuides = growGuides(*guides.scene, threaded, interrupter);
        guidePoints = &grownGuides;
    }
    const StrandSet& g = *guidePoints;
    if (g.empty()) throw ValueError(guides.where + ": no guides: interpolation needs at least one");
    for (std::size_t i = 0; i < g.numStrands(); ++i) {
        const std::size_t n = g.size(i);
        if (n < 2) throw ValueError(guides.where + ": guide strand " + std::to_string(i) + ": " + std::to_string(n) + " vertex; a guide needs at least 2");
        if (!(polylineLength(g.positions.data() + g.begin(i), n) > 0.0)) {
            throw ValueError(guides.where + ": guide strand " + std::to_string(i) + ": zero length; a guide must have a positive length");
        }
    }
    GuideContext context;
    context.groups = guides.groups;
    context.frames = params.frames;
    if (guides.scene && params.frames == FrameRule::Surface) context.normals = sceneGuideNormals(*guides.scene);
    res.strands = interpolatePoints(g, roots, params.points, context, threaded, interrupter, &res.groups, &rootGroups, &res.binding);
    res.guides = g.numStrands();
    res.guidesEnteringHead = countStrandsEnteringHead(g, head, headTolerance(head), threaded);
    return guidePoints;
}

/// The helicoid method: strand guides fitted to a scene first, the helicoids blended by
/// interpolateHelicoids() and, unless a scene is asked for, grown (a scene's guides too, into
/// @a grownGuides). Returns the guides as strands, or null with a scene asked for.
const StrandSet* interpolateByHelicoids(const InterpolationGuides& guides, const InterpolationRoots& roots, const HeadObstacle& head,
                                        const InterpolateParams& params, bool threaded, openvdb::util::NullInterrupter* interrupter,
                                        std::chrono::steady_clock::time_point t0, InterpolateResult& res, StrandSet& grownGuides)
{
    const StrandSet* guidePoints = guides.strands;
    Scene fitted;
    if (guides.strands) {
        if (guides.strands->empty()) throw ValueError(guides.where + ": no guides: interpolation needs at least one");
        fitted = guideSceneFromStrands(*guides.strands, FitParams{}, guides.where, threaded, interrupter);
        res.fitSeconds = secondsSince(t0);
    }
    const Scene& scene = guides.strands ? fitted : *guides.scene;
    if (scene.guides.empty()) throw ValueError(guides.where + ": no guides: interpolation needs at least one");
    validateGuideScene(scene);
    const std::vector<Vec3d> guideNormals = roots.normals.empty() ? std::vector<Vec3d>() : sceneGuideNormals(scene);
    res.scene = interpolateHelicoids(scene, roots, params.helicoid, guideNormals, threaded, interrupter);
    res.scene.seed = params.seed;
    res.guides = scene.guides.size();
    if (!params.returnScene) {
        GrowOptions grow;
        grow.maxVertices = params.helicoid.maxVertices;
        res.strands = growScene(res.scene, grow, threaded, interrupter);
        if (!guides.strands) {
            grownGuides = growGuides(scene, threaded, interrupter);
            guidePoints = &grownGuides;
        }
        res.guidesEnteringHead = countStrandsEnteringHead(*guidePoints, head, headTolerance(head), threaded);
    }
    return guidePoints;
}

/// Length (GroomControls.h), then the head: no new hair deeper inside it than its root, the
/// hair swept out along its length (HeadCollision.h).
void cutAndKeepOutOfHead(InterpolateResult& res, const std::vector<float>& length, const HeadObstacle& head, bool threaded)
{
    if (!length.empty()) res.cut = cutStrands(res.strands, length, threaded);
    if (!head.empty()) {
        const HeadCollisionStats hc = resolveHeadCollisions(res.strands, head, rootDepthAllowance(res.strands, head, threaded), {}, threaded);
        res.pushedOut = hc.strandsMoved;
        res.verticesTooDeep = hc.verticesTooDeep;
    }
}

/// Curl, clumps (within groups), frizz on the hair as it lies, and only the vertices they move
/// into the head pushed out, one by one: a curl that dips into the scalp is flattened against
/// it, not turned away with the rest of the strand (a sweep would flare curly hair out).
void groomHair(InterpolateResult& res, const InterpolateParams& params, const std::vector<std::uint32_t>& rootGroups,
               const HeadObstacle& head, bool threaded, openvdb::util::NullInterrupter* interrupter)
{
    const bool points = params.method == InterpolationMethod::Points;
    GroomParams groom = params.groom;
    groom.seed = params.seed;
    groom.maxVertices = points ? params.points.maxVertices : params.helicoid.maxVertices;
    res.groom = applyGroomControls(res.strands, groom, rootGroups, threaded, interrupter);
    if (!head.empty()) {
        HeadCollisionParams vertexOnly;
        vertexOnly.passes = 0;
        const HeadCollisionStats hc = resolveHeadCollisions(res.strands, head, rootDepthAllowance(res.strands, head, threaded), vertexOnly, threaded);
        res.groomPushedOut = hc.strandsMoved;
        res.verticesTooDeep = hc.verticesTooDeep;
    }
}

/// The share of the new hair (all of it, or kVolumeSample strands spread over it) leaving the
/// guides' hair volume at the guides' suggested voxel size.
void measureLeavingVolume(InterpolateResult& res, const StrandSet& guidePoints, bool threaded)
{
    res.volumeVoxel = suggestVoxelSize(guidePoints);
    const std::size_t S = res.strands.numStrands();
    if (S <= kVolumeSample) {
        res.volumeSample = S;
        res.leavingVolume = countStrandsLeavingVolume(res.strands, guidePoints, res.volumeVoxel, threaded);
    } else {
        std::vector<char> pick(S, 0);
        for (std::size_t k = 0; k < kVolumeSample; ++k) pick[k * S / kVolumeSample] = 1;
        res.volumeSample = kVolumeSample;
        res.leavingVolume = countStrandsLeavingVolume(selectStrands(res.strands, pick), guidePoints, res.volumeVoxel, threaded);
    }
}

} // namespace

const char* interpolationMethodName(InterpolationMethod method) { return method == InterpolationMethod::Points ? "points" : "helicoid"; }

InterpolationMethod interpolationMethodFromName(const std::string& name)
{
    if (name == "points") return InterpolationMethod::Points;
    if (name == "helicoid") return InterpolationMethod::Helicoid;
    throw ValueError("method '" + name + "' is not one of points, helicoid");
}

const char* frameRuleName(FrameRule frames) { return frames == FrameRule::World ? "world" : "surface"; }

FrameRule frameRuleFromName(const std::string& name)
{
    if (name == "world") return FrameRule::World;
    if (name == "surface") return FrameRule::Surface;
    throw ValueError("frames '" + name + "' is not one of world, surface");
}

const ParamTable<InterpolateParams>& interpolateParameters()
{
    using P = InterpolateParams;
    static const ParamTable<P> table = [] {
        ParamTable<P> t;
        auto add = [&](Param<P> p) { t.push_back(std::move(p)); };
        auto method = makeParam<P>("method", "points (the guides' own points, by group and likeness) or helicoid (their helicoid parameters, Piuze et al.)", "",
                                   named<P>([](P& p) -> InterpolationMethod& { return p.method; }, interpolationMethodName, interpolationMethodFromName));
        method.choices = {"points", "helicoid"};
        add(method);
        const auto points = [](P& p) -> PointInterpolationParams& { return p.points; };
        for (Param<P>& q : nestedParams<P>(pointInterpolationParameters(), points)) add(std::move(q));
        for (Param<P>& q : nestedParams<P>(groomParameters(), [](P& p) -> GroomParams& { return p.groom; })) add(std::move(q));
        for (Param<P>& q : nestedParams<P>(helicoidInterpolationParameters(), [](P& p) -> HelicoidInterpolationParams& { return p.helicoid; })) add(std::move(q));
        add(guideNeighborsParam<P>());
        auto frames = makeParam<P>("frames", "world (guides carried as they are) or surface (turned with the roots' normals, Sec. 4.3; flares long hair)", "",
                                   named<P>([](P& p) -> FrameRule& { return p.frames; }, frameRuleName, frameRuleFromName));
        frames.choices = {"world", "surface"};
        add(frames);
        add(makeParam<P>("seed", "Seed of the density draw, clumps, curl phases, frizz and waviness noise (and of roots spread on a scalp)", "",
                         member<P>([](P& p) -> std::uint64_t& { return p.seed; })));
        // One cap for both methods.
        add(makeParam<P>("max-vertices", "Refuse requests that would make more vertices (12 bytes each), estimated before any work", "",
                         ParamAccess<P, std::uint64_t>{[](const P& p) { return std::uint64_t(p.helicoid.maxVertices); },
                                                       [](P& p, std::uint64_t v) { p.helicoid.maxVertices = p.points.maxVertices = v; }}));
        add(makeAxisParam<P>("up", "Reference axis of surface frames (and of roots spread on a scalp)", [](P& p) -> Vec3d& { return p.helicoid.up; }));
        return t;
    }();
    return table;
}

InterpolateResult interpolateGuides(const InterpolationGuides& guides, const InterpolationRoots& rootsIn, const HeadObstacle& head,
                                    const InterpolateParams& params, bool threaded, openvdb::util::NullInterrupter* interrupter)
{
    checkArguments(guides, rootsIn, params);
    const InterpolationRoots roots = keptRoots(rootsIn, params);

    InterpolateResult res;
    res.roots = rootsIn.positions.size();
    res.rootsDropped = res.roots - roots.positions.size();
    std::vector<std::uint32_t> rootGroups;
    StrandSet grownGuides;  // a scene's guides as strands (the volume measure, the head share)
    const auto t0 = std::chrono::steady_clock::now();
    const StrandSet* guidePoints =
        params.method == InterpolationMethod::Points
            ? interpolateByPoints(guides, roots, head, params, threaded, interrupter, res, rootGroups, grownGuides)
            : interpolateByHelicoids(guides, roots, head, params, threaded, interrupter, t0, res, grownGuides);
    if (!params.returnScene) cutAndKeepOutOfHead(res, roots.length, head, threaded);
    if (!params.returnScene && groomsHair(params.groom)) groomHair(res, params, rootGroups, head, threaded, interrupter);
    res.enteringHead = countStrandsEnteringHead(res.strands, head, headTolerance(head), threaded);
    if (!params.returnScene && guidePoints) measureLeavingVolume(res, *guidePoints, threaded);
    res.seconds = secondsSince(t0) - res.fitSeconds;
    return res;
}

void writeGroomAbc(const std::string& path, const StrandSet& guides, const std::vector<std::int32_t>& guideGroups,
                   const InterpolateResult& result)
{
    const std::size_t G = guides.numStrands(), S = result.strands.numStrands();
    const std::string where = "writeGroomAbc(" + path + ")";
    if (result.binding.guides.size() != 3 * S || result.binding.weights.size() != 3 * S)
        throw ValueError(where + ": the result has no guide binding for its " + std::to_string(S) + " strands (points interpolation makes one)");
    if (!guideGroups.empty() && guideGroups.size() != G)
        throw ValueError(where + ": " + std::to_string(guideGroups.size()) + " guide groups for " + std::to_string(G) + " guides: one per guide");
    for (const std::int32_t g : result.binding.guides)
        if (g < 0 || std::size_t(g) >= G) throw ValueError(where + ": guide " + std::to_string(g) + " bound, of " + std::to_string(G) + " guides");
    StrandSet guideCopy = guides, hair = result.strands;
    guideCopy.strandId.resize(G);
    for (std::size_t i = 0; i < G; ++i) guideCopy.strandId[i] = std::int32_t(i);
    hair.strandId.resize(S);
    for (std::size_t i = 0; i < S; ++i) hair.strandId[i] = std::int32_t(G + i);
    AbcCurves g, h;
    g.name = "guides";
    g.strands = &guideCopy;
    g.guides = true;
    g.groupId = guideGroups;
    h.name = "hair";
    h.strands = &hair;
    h.closestGuides = result.binding.guides;  // guide i has groom_id i
    h.guideWeights = result.binding.weights;
    if (!guideGroups.empty()) {
        h.groupId.resize(S);
        for (std::size_t i = 0; i < S; ++i) h.groupId[i] = guideGroups[std::size_t(result.binding.guides[3 * i])];
    }
    writeAbc(path, {std::move(g), std::move(h)});
}

} // namespace vdbhair
