#include "Prepare.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/Parallel.h>
#include <vdbhair/strands/Resample.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>

namespace vdbhair {

void PrepareParams::validate() const
{
    if (points == 1) throw ParamError<ValueError>({paramName(prepareParameters(), "points"), " 1: a strand needs at least 2 vertices (0 keeps them)"});
    if (!(headCrop >= 0.0) || !std::isfinite(headCrop)) {
        throw ParamError<ValueError>({paramName(prepareParameters(), "head-crop"),
                                      " " + std::to_string(headCrop) + ": must be a finite factor, 0 or more (0 keeps the whole head)"});
    }
    align.validate();
}

void transformStrands(StrandSet& s, const Similarity& t)
{
    forEachIndex(s.positions.size(), true, [&](std::size_t i) {
        const Vec3f& p = s.positions[i];
        const Vec3d q = t.apply(Vec3d(p.x(), p.y(), p.z()));
        s.positions[i] = Vec3f(float(q.x()), float(q.y()), float(q.z()));
    }, 4096);
    for (float& w : s.thickness) w = float(w * t.scale);
    s.defaults.thickness = float(s.defaults.thickness * t.scale);
}

RootDepth rootDepthFromName(const std::string& name)
{
    if (name == "keep") return RootDepth::Keep;
    if (name == "surface") return RootDepth::Surface;
    throw ParamError<ValueError>({paramName(prepareParameters(), "root-depth"), " '" + name + "': must be keep or surface"});
}

const char* rootDepthName(RootDepth depth)
{
    return depth == RootDepth::Keep ? "keep" : "surface";
}

const ParamTable<PrepareParams>& prepareParameters()
{
    using P = PrepareParams;
    static const ParamTable<P> table = [] {
        ParamTable<P> t;
        auto points = makeParam<P>("points", "Resample every strand to exactly N vertices, at least 2, equally spaced in arc length, root and tip kept", "",
                                   member<P>([](P& p) -> std::size_t& { return p.points; }));
        points.min = 0;
        points.zeroMeans = "keep them";
        t.push_back(points);
        auto strands = makeParam<P>("strands", "Keep N strands with evenly spread roots (farthest-point sampling of the roots; all when fewer)", "",
                                    member<P>([](P& p) -> std::size_t& { return p.strands; }));
        strands.min = 0;
        strands.zeroMeans = "keep all";
        strands.keyword = "count";
        t.push_back(strands);
        auto overlap = makeParam<P>("overlap",
                                    "Aligning to another head: the share of nearest point pairs ICP keeps at each iteration (necks cut at "
                                    "different heights)", "",
                                    member<P>([](P& p) -> double& { return p.align.overlap; }));
        overlap.min = 0.0;
        overlap.aboveMin = true;
        overlap.max = 1.0;
        t.push_back(overlap);
        auto crop = makeParam<P>("head-crop",
                                 "Aligning by ICP: use the groom's head vertices within this many times the roots' radius of their "
                                 "centroid (the head, not a bust's shoulders)", "",
                                 member<P>([](P& p) -> double& { return p.headCrop; }));
        crop.min = 0.0;
        crop.zeroMeans = "every vertex";
        t.push_back(crop);
        t.push_back(makeAxisParam<P>("target-up",
                                     "Aligning by ICP: the common head's up axis (the groom's up is from its head to its roots; ICP "
                                     "starts only from rotations that keep the two within 90 degrees)",
                                     [](P& p) -> Vec3d& { return p.targetUp; }));
        auto depth = makeParam<P>("root-depth",
                                  "Fixing penetration: keep (a root inside the head stays, its strand no deeper than it) or surface (the "
                                  "strand is first moved out along the head's normal until its root is on the surface: roots under a new "
                                  "scalp after aligning)", "",
                                  named<P>([](P& p) -> RootDepth& { return p.rootDepth; }, rootDepthName, rootDepthFromName));
        depth.choices = {rootDepthName(RootDepth::Keep), rootDepthName(RootDepth::Surface)};
        t.push_back(depth);
        return t;
    }();
    return table;
}

std::size_t liftRootsToSurface(StrandSet& strands, const HeadObstacle& head, bool threaded)
{
    std::vector<char> lifted(strands.numStrands(), 0);
    forEachRange(strands.numStrands(), threaded, 64, [&](const tbb::blocked_range<std::size_t>& range) {
        HeadObstacle::Probe probe(head);  // one per range: a probe holds a grid accessor
        for (std::size_t i = range.begin(); i != range.end(); ++i) {
            const Vec3f& root = strands.root(i);
            Vec3d p(root.x(), root.y(), root.z());
            const Vec3d before = p;
            if (!probe.pushOut(p, 0.0)) continue;
            const Vec3f delta(float(p.x() - before.x()), float(p.y() - before.y()), float(p.z() - before.z()));
            for (std::size_t v = strands.begin(i); v < strands.end(i); ++v) strands.positions[v] += delta;
            lifted[i] = 1;
        }
    });
    std::size_t n = 0;
    for (char l : lifted) n += std::size_t(l);
    return n;
}

TriangleMesh cropMeshToRoots(const TriangleMesh& mesh, const StrandSet& strands, double factor)
{
    Vec3d c(0.0);
    for (std::size_t i = 0; i < strands.numStrands(); ++i) c += Vec3d(strands.root(i));
    c /= double(std::max<std::size_t>(1, strands.numStrands()));
    double radius = 0.0;
    for (std::size_t i = 0; i < strands.numStrands(); ++i) radius = std::max(radius, (Vec3d(strands.root(i)) - c).length());
    const double limit2 = (factor * radius) * (factor * radius);
    TriangleMesh out;
    std::vector<std::uint32_t> index(mesh.vertices.size(), std::numeric_limits<std::uint32_t>::max());
    for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
        if ((Vec3d(mesh.vertices[i]) - c).lengthSqr() > limit2) continue;
        index[i] = std::uint32_t(out.vertices.size());
        out.vertices.push_back(mesh.vertices[i]);
    }
    for (const auto& t : mesh.triangles) {
        if (t[0] >= index.size() || t[1] >= index.size() || t[2] >= index.size()) continue;
        const std::array<std::uint32_t, 3> kept{index[t[0]], index[t[1]], index[t[2]]};
        if (kept[0] != std::numeric_limits<std::uint32_t>::max() && kept[1] != std::numeric_limits<std::uint32_t>::max() &&
            kept[2] != std::numeric_limits<std::uint32_t>::max()) {
            out.triangles.push_back(kept);
        }
    }
    return out;
}

PrepareReport prepareStrands(StrandSet& strands, const PrepareParams& params, const TriangleMesh* head,
                             const TriangleMesh* alignTo, const HeadObstacle* fixHead, bool threaded)
{
    params.validate();
    if (alignTo && !head) {
        throw ValueError("prepareStrands: aligning to a common head needs the groom's own head mesh (head): the groom's head is "
                         "fitted to the common head, not the strands");
    }
    PrepareReport r;
    r.inputStrands = strands.numStrands();
    r.inputVertices = strands.numVertices();

    // 1. Even roots.
    if (params.strands > 0) {
        RootSelection sel;
        strands = subsampleStrands(strands, params.strands, &sel, threaded);
        sel.strands.clear();
        r.subsample = std::move(sel);
        r.requestedStrands = params.strands;
    }
    // 2. The groom's head onto the common head; the strands move with it.
    if (alignTo) {
        const bool sameMesh = head->vertices.size() == alignTo->vertices.size() && head->triangles == alignTo->triangles;
        if (sameMesh || params.headCrop == 0.0 || strands.empty()) {
            r.align = alignMeshes(*head, *alignTo, params.align, threaded);
            r.headVertices = head->vertices.size();
        } else {
            const TriangleMesh cropped = cropMeshToRoots(*head, strands, params.headCrop);
            if (cropped.vertices.size() < 3) {
                throw ValueError("prepareStrands: " + std::to_string(cropped.vertices.size()) + " vertices of the groom's head lie within " +
                                 std::to_string(params.headCrop) + " x the roots' radius of their centroid; is it the head of these strands, "
                                 "in their frame? (headCrop 0 uses the whole head)");
            }
            AlignParams align = params.align;
            if (params.targetUp.lengthSqr() > 0.0) {
                Vec3d roots(0.0), headCentre(0.0);
                for (std::size_t i = 0; i < strands.numStrands(); ++i) roots += Vec3d(strands.root(i));
                // The whole head's centroid (the cut one's is near the roots, by construction).
                for (const Vec3f& v : head->vertices) headCentre += Vec3d(v);
                align.sourceUp = roots / double(strands.numStrands()) - headCentre / double(head->vertices.size());
                align.targetUp = params.targetUp;
            }
            r.align = alignMeshes(cropped, *alignTo, align, threaded);
            r.headVertices = cropped.vertices.size();
        }
        transformStrands(strands, r.align->transform);
    }
    // 3. One vertex count (checked before resampleStrands() multiplies it out).
    if (params.points >= 2) {
        const std::size_t limit = std::numeric_limits<std::uint32_t>::max();
        if (strands.numStrands() > 0 && params.points > limit / strands.numStrands()) {
            throw ParamError<ValueError>({paramName(prepareParameters(), "points"), " " + std::to_string(params.points) + ": " + std::to_string(strands.numStrands()) +
                                                                                         " strands of that many vertices exceed the limit of 2^32-1 vertices"});
        }
        strands = resampleStrands(strands, params.points);
    }
    r.points = params.points;
    // 4. Out of the head, as deep as each root at most.
    if (fixHead && !fixHead->empty()) {
        r.fixed = true;
        r.tolerance = headTolerance(*fixHead);
        r.fixHead = fixHead->describe(false);
        r.enteringBefore = countStrandsEnteringHead(strands, *fixHead, r.tolerance, threaded);
        if (params.rootDepth == RootDepth::Surface) r.rootsLifted = liftRootsToSurface(strands, *fixHead, threaded);
        r.collision = resolveHeadCollisions(strands, *fixHead, rootDepthAllowance(strands, *fixHead, threaded), params.collision, threaded);
        r.enteringAfter = countStrandsEnteringHead(strands, *fixHead, r.tolerance, threaded);
    }
    r.strands = strands.numStrands();
    r.vertices = strands.numVertices();
    return r;
}

nlohmann::json toJson(const Similarity& t)
{
    nlohmann::json rot = nlohmann::json::array(), matrix = nlohmann::json::array();
    for (int i = 0; i < 3; ++i) {
        rot.push_back({t.rotation(i, 0), t.rotation(i, 1), t.rotation(i, 2)});
        matrix.push_back({t.scale * t.rotation(i, 0), t.scale * t.rotation(i, 1), t.scale * t.rotation(i, 2), t.translation[i]});
    }
    matrix.push_back({0.0, 0.0, 0.0, 1.0});
    return {{"scale", t.scale}, {"rotation", rot}, {"translation", {t.translation.x(), t.translation.y(), t.translation.z()}},
            {"matrix", matrix}};
}

nlohmann::json toJson(const PrepareReport& r)
{
    nlohmann::json j = {{"input_strands", r.inputStrands}, {"input_vertices", r.inputVertices},
                        {"strands", r.strands},            {"vertices", r.vertices},
                        {"points", r.points ? nlohmann::json(r.points) : nlohmann::json(nullptr)}};
    if (r.subsample) {
        j["subsample"] = {{"requested", r.requestedStrands}, {"kept", r.strands},
                          {"min_root_spacing", r.subsample->minSpacing}, {"coverage_radius", r.subsample->coverageRadius}};
    } else {
        j["subsample"] = nullptr;
    }
    if (r.align) {
        nlohmann::json a = toJson(r.align->transform);
        a["method"] = alignMethodName(r.align->method);
        a["residual_rms"] = r.align->rms;
        a["residual_max"] = r.align->max;
        a["residual_rms_all"] = r.align->rmsAll;
        a["points"] = r.align->pairs;
        a["head_vertices"] = r.headVertices;
        a["iterations"] = r.align->iterations;
        a["start"] = r.align->start;
        j["align"] = a;
    } else {
        j["align"] = nullptr;
    }
    if (r.fixed) {
        j["fix_penetration"] = {{"head", r.fixHead},
                                {"entering_before", r.enteringBefore},
                                {"entering_after", r.enteringAfter},
                                {"strands_moved", r.collision.strandsMoved},
                                {"roots_lifted", r.rootsLifted},
                                {"vertices_too_deep", r.collision.verticesTooDeep},
                                {"tolerance", r.tolerance}};
    } else {
        j["fix_penetration"] = nullptr;
    }
    return j;
}

} // namespace vdbhair
