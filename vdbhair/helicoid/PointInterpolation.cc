#include "PointInterpolation.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/Format.h>
#include <vdbhair/Progress.h>
#include <vdbhair/Rotation.h>
#include <vdbhair/helicoid/ShepardWeights.h>
#include <vdbhair/strands/Measures.h>
#include <vdbhair/strands/Resample.h>

#include <openvdb/math/Mat.h>
#include <openvdb/math/Mat3.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <memory>

namespace vdbhair {

namespace {

constexpr std::size_t kLikenessSamples = 16;

Vec3d toD(const Vec3f& v) { return Vec3d(v.x(), v.y(), v.z()); }

/// Root-relative points of a polyline at fractions 1/16 .. 16/16 of its length.
std::array<Vec3f, kLikenessSamples> likenessSignature(const Vec3f* p, std::size_t n)
{
    std::array<Vec3f, kLikenessSamples + 1> s;
    resamplePolyline(p, n, kLikenessSamples + 1, s.data());
    std::array<Vec3f, kLikenessSamples> out;
    for (std::size_t j = 0; j < kLikenessSamples; ++j) out[j] = s[j + 1] - s[0];
    return out;
}

double signatureDistance(const std::array<Vec3f, kLikenessSamples>& a, double la, const std::array<Vec3f, kLikenessSamples>& b, double lb)
{
    const double longer = std::max(la, lb);
    if (!(longer > 0.0)) return 0.0;
    double sum = 0.0;
    for (std::size_t j = 0; j < kLikenessSamples; ++j) sum += double((a[j] - b[j]).length());
    return sum / double(kLikenessSamples) / longer;
}

/// The guides of one group: their roots in a k-d tree, and the guide index of each.
struct GroupLocator
{
    std::vector<std::uint32_t> members;
    std::unique_ptr<GuideLocator> locator;
};

/// The arguments' counts and ranges, before any work.
void checkArguments(std::size_t G, std::size_t R, const InterpolationRoots& roots, const PointInterpolationParams& params,
                    const GuideContext& context)
{
    if (G == 0) throw ValueError("no guides: interpolation needs at least one guide");
    if (R == 0) throw ValueError("no roots: interpolation needs at least one root");
    if (params.neighbors < 1) throw ValueError("neighbors " + std::to_string(params.neighbors) + ": must be at least 1");
    if (!(params.likeness > 0.0) || !std::isfinite(params.likeness)) {
        throw ParamError<ValueError>({paramName(pointInterpolationParameters(), "likeness"),
                                      " " + formatNumber(params.likeness) + ": must be a positive fraction of the guide length"});
    }
    if (!roots.normals.empty() && roots.normals.size() != R) {
        throw ValueError(std::to_string(roots.normals.size()) + " root normals for " + std::to_string(R) + " roots");
    }
    if (!roots.groups.empty() && roots.groups.size() != R) {
        throw ValueError(std::to_string(roots.groups.size()) + " root group ids for " + std::to_string(R) + " roots: one per root");
    }
    if (!context.normals.empty() && context.normals.size() != G) {
        throw ValueError(std::to_string(context.normals.size()) + " guide normals for " + std::to_string(G) + " guides");
    }
    if (!context.groups.empty() && context.groups.size() != G) {
        throw ValueError(std::to_string(context.groups.size()) + " guide group ids for " + std::to_string(G) + " guides: one per guide");
    }
    if (context.frames == FrameRule::Surface && roots.normals.empty()) throw ValueError("surface frames need root normals; the roots have none");
}

/// What blending needs of each guide: arc lengths (double), root and likeness signature.
struct GuideTable
{
    std::vector<std::vector<double>> arc;
    std::vector<Vec3d> roots;
    std::vector<std::array<Vec3f, kLikenessSamples>> signature;
    std::size_t maxCount = 0;  ///< the most vertices of a guide
};

/// The guides' table, checking each guide: at least 2 finite vertices and a positive length.
GuideTable tabulateGuides(const StrandSet& guides)
{
    const std::size_t G = guides.numStrands();
    GuideTable t;
    t.arc.resize(G);
    t.roots.resize(G);
    t.signature.resize(G);
    for (std::size_t g = 0; g < G; ++g) {
        const std::size_t n = guides.size(g), b = guides.begin(g);
        if (n < 2) throw ValueError("guide " + std::to_string(g) + ": has " + std::to_string(n) + " vertex; a guide needs at least 2");
        std::vector<double>& arc = t.arc[g];
        arc.resize(n);
        arc[0] = 0.0;
        for (std::size_t k = 0; k < n; ++k) {
            const Vec3f& p = guides.positions[b + k];
            if (!std::isfinite(p.x()) || !std::isfinite(p.y()) || !std::isfinite(p.z())) {
                throw ValueError("guide " + std::to_string(g) + ": vertex " + std::to_string(k) + " is not finite");
            }
            if (k > 0) arc[k] = arc[k - 1] + double((p - guides.positions[b + k - 1]).length());
        }
        if (!(arc.back() > 0.0)) throw ValueError("guide " + std::to_string(g) + ": zero length: a guide must have a positive length");
        t.roots[g] = toD(guides.positions[b]);
        t.signature[g] = likenessSignature(guides.positions.data() + b, n);
        t.maxCount = std::max(t.maxCount, n);
    }
    return t;
}

/// The vertex cap (each new hair holds at most the longest guide's count) and finite roots.
void checkRoots(const InterpolationRoots& roots, std::size_t maxCount, std::size_t maxVertices)
{
    const std::size_t R = roots.positions.size();
    const double estimate = double(R) * double(maxCount);
    if (estimate > double(maxVertices)) {
        throw LimitError(std::to_string(R) + " strands would hold up to " + formatNumber(estimate) + " vertices, more than the cap of " +
                         std::to_string(maxVertices) + " (fewer roots)");
    }
    for (std::size_t i = 0; i < R; ++i) {
        const Vec3d& p = roots.positions[i];
        if (!std::isfinite(p.x()) || !std::isfinite(p.y()) || !std::isfinite(p.z())) throw ValueError("root " + std::to_string(i) + " is not finite");
    }
}

/// The guide groups: a k-d tree of each group's guide roots, group ids in ascending order.
struct GuideGroups
{
    std::vector<GroupLocator> groups;
    std::vector<std::uint32_t> guideGroup;  ///< per guide
    std::vector<std::uint32_t> rootGroup;   ///< per root: given, or filled in by weighRoots()
    std::unique_ptr<GuideLocator> all;      ///< every guide, when the roots' groups follow their nearest guide's
};

GuideGroups groupGuides(const std::vector<Vec3d>& guideRoots, const InterpolationRoots& roots, const GuideContext& context)
{
    const std::size_t G = guideRoots.size();
    std::map<std::int32_t, std::size_t> groupIndex;
    for (std::size_t g = 0; g < G; ++g) groupIndex.emplace(context.groups.empty() ? 0 : context.groups[g], 0);
    std::size_t M = 0;
    for (auto& e : groupIndex) e.second = M++;
    GuideGroups gg;
    gg.groups.resize(M);
    gg.guideGroup.assign(G, 0);
    for (std::size_t g = 0; g < G; ++g) {
        gg.guideGroup[g] = std::uint32_t(groupIndex.at(context.groups.empty() ? 0 : context.groups[g]));
        gg.groups[gg.guideGroup[g]].members.push_back(std::uint32_t(g));
    }
    for (GroupLocator& gl : gg.groups) {
        std::vector<Vec3d> r;
        for (std::uint32_t g : gl.members) r.push_back(guideRoots[g]);
        gl.locator = std::make_unique<GuideLocator>(std::move(r));
    }
    gg.rootGroup.assign(roots.positions.size(), 0);
    for (std::size_t i = 0; i < roots.groups.size(); ++i) {
        const auto it = groupIndex.find(roots.groups[i]);
        if (it == groupIndex.end()) {
            throw ValueError("root " + std::to_string(i) + ": group " + std::to_string(roots.groups[i]) + " has no guides; every root group needs at least one");
        }
        gg.rootGroup[i] = std::uint32_t(it->second);
    }
    if (roots.groups.empty() && M > 1) gg.all = std::make_unique<GuideLocator>(guideRoots);
    return gg;
}

/// Guide normals for surface frames, unit: given, or those of the roots nearest the guides.
std::vector<Vec3d> guideNormals(const GuideContext& context, bool surface, const InterpolationRoots& roots,
                                const std::vector<Vec3d>& guideRoots)
{
    std::vector<Vec3d> gn = context.normals;
    if (surface && gn.empty()) {
        const GuideLocator near(roots.positions);
        for (const Vec3d& r : guideRoots) gn.push_back(roots.normals[near.nearest(r)]);
    }
    for (Vec3d& n : gn) {
        if (!(n.length() > 0.0) || !std::isfinite(n.length())) throw ValueError("a guide normal is zero or not finite");
        n.normalize();
    }
    return gn;
}

/// Steps 1-3: each root's guide weights (its group's nearest guides, faded, and with shape
/// grouping only those shaped like the nearest) and its vertex count, the weighted mean of its
/// guides' counts, into @a out's offsets.
std::vector<std::vector<GuideWeight>> weighRoots(const StrandSet& guides, const InterpolationRoots& roots, const GuideTable& table,
                                                 GuideGroups& gg, const PointInterpolationParams& params, bool threaded, StrandSet& out)
{
    const std::size_t R = roots.positions.size();
    std::vector<std::vector<GuideWeight>> weights(R);
    out.offsets.assign(R + 1, 0);
    auto weigh = [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
            const Vec3d& x = roots.positions[i];
            const std::uint32_t group = roots.groups.empty() ? (gg.all ? gg.guideGroup[gg.all->nearest(x)] : 0u) : gg.rootGroup[i];
            gg.rootGroup[i] = group;
            const GroupLocator& gl = gg.groups[group];
            std::vector<GuideWeight>& ws = weights[i];
            gl.locator->fadedWeights(x, params.neighbors, ws);
            for (GuideWeight& w : ws) w.guide = gl.members[w.guide];
            if (params.grouping == GuideGrouping::Shape && ws.size() > 1) {
                const std::uint32_t nearest = ws.front().guide;  // fadedWeights() lists the nearest first
                const double ln = table.arc[nearest].back();
                double sum = 0.0;
                for (GuideWeight& w : ws) {
                    const double u = signatureDistance(table.signature[nearest], ln, table.signature[w.guide], table.arc[w.guide].back()) /
                                     params.likeness;
                    const double f = u < 1.0 ? (1.0 - u * u) * (1.0 - u * u) : 0.0;
                    w.weight *= f;
                    sum += w.weight;
                }
                // The nearest guide always has f = 1 and a positive faded weight, so sum > 0.
                ws.erase(std::remove_if(ws.begin(), ws.end(), [](const GuideWeight& w) { return !(w.weight > 0.0); }), ws.end());
                for (GuideWeight& w : ws) w.weight /= sum;
            }
            double n = 0.0;
            for (const GuideWeight& w : ws) n += w.weight * double(guides.size(w.guide));
            out.offsets[i + 1] = std::uint32_t(std::max<long>(2, std::lround(n)));
        }
    };
    if (threaded) tbb::parallel_for(tbb::blocked_range<std::size_t>(0, R, 1024), weigh);
    else weigh(tbb::blocked_range<std::size_t>(0, R));
    for (std::size_t i = 0; i < R; ++i) out.offsets[i + 1] += out.offsets[i];
    return weights;
}

/// Step 4: each new hair's points, its root plus the weighted guides' root-relative points at
/// the same fractions of their length (turned from the guide's normal to the root's with surface
/// frames). @a out holds the offsets.
void blendPoints(const StrandSet& guides, const InterpolationRoots& roots, const GuideTable& table,
                 const std::vector<std::vector<GuideWeight>>& weights, const std::vector<Vec3d>& gn, bool surface, bool threaded,
                 openvdb::util::NullInterrupter* interrupter, StrandSet& out)
{
    const std::size_t R = roots.positions.size();
    out.positions.resize(out.offsets.back());
    ProgressCounter progress(interrupter, "blending guide points", R, "strands");
    auto blend = [&](const tbb::blocked_range<std::size_t>& r) {
        if (progress.stopped()) return;
        std::vector<Vec3d> acc;
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
            const std::size_t n = out.size(i);
            acc.assign(n, Vec3d(0.0));
            const Vec3d rootNormal = surface ? roots.normals[i].unit() : Vec3d(0.0);
            for (const GuideWeight& w : weights[i]) {
                const std::vector<double>& s = table.arc[w.guide];
                const Vec3d& guideRoot = table.roots[w.guide];
                const Vec3f* p = guides.positions.data() + guides.begin(w.guide);
                const std::size_t m = s.size();
                openvdb::math::Mat3d rot = openvdb::math::Mat3d::identity();
                if (surface) rot = rotationMatrixBetween(gn[w.guide], rootNormal);
                std::size_t seg = 0;
                if (m == n) {
                    // The same count: the guide's own vertices (a root on a guide's root is that guide).
                    for (std::size_t k = 0; k < n; ++k) {
                        Vec3d offset = toD(p[k]) - guideRoot;
                        if (surface) offset = rot.transform(offset);
                        acc[k] += w.weight * offset;
                    }
                    continue;
                }
                for (std::size_t k = 0; k < n; ++k) {
                    // Resample by arc length: the point at k / (n - 1) of the guide's length.
                    const double target = s.back() * double(k) / double(n - 1);
                    while (seg + 2 < m && s[seg + 1] < target) ++seg;
                    const double len = s[seg + 1] - s[seg];
                    double f = len > 0.0 ? std::clamp((target - s[seg]) / len, 0.0, 1.0) : 0.0;
                    if (k == n - 1) f = 1.0, seg = m - 2;
                    const Vec3d a = toD(p[seg]), b = toD(p[seg + 1]);
                    Vec3d offset = a + (b - a) * f - guideRoot;
                    if (surface) offset = rot.transform(offset);
                    acc[k] += w.weight * offset;
                }
            }
            const std::size_t b = out.begin(i);
            for (std::size_t k = 0; k < n; ++k) {
                const Vec3d q = roots.positions[i] + acc[k];
                out.positions[b + k] = Vec3f(float(q.x()), float(q.y()), float(q.z()));
            }
        }
        progress.add(r.size());
    };
    if (threaded) tbb::parallel_for(tbb::blocked_range<std::size_t>(0, R, 256), blend);
    else blend(tbb::blocked_range<std::size_t>(0, R));
    if (progress.stopped()) throw InterruptedError("interpolatePoints: interrupted");
}

/// Each hair's three heaviest guides (ties to the lower index) and their weights renormalized
/// to sum to 1; fewer than three repeat the heaviest with weight 0.
void bindHeaviestGuides(const std::vector<std::vector<GuideWeight>>& weights, GuideBinding& binding)
{
    const std::size_t R = weights.size();
    binding.guides.assign(3 * R, 0);
    binding.weights.assign(3 * R, 0.0f);
    std::vector<GuideWeight> top;
    for (std::size_t i = 0; i < R; ++i) {
        top = weights[i];
        std::sort(top.begin(), top.end(), [](const GuideWeight& a, const GuideWeight& b) {
            return a.weight > b.weight || (a.weight == b.weight && a.guide < b.guide);
        });
        top.resize(std::min<std::size_t>(top.size(), 3));
        double sum = 0.0;
        for (const GuideWeight& w : top) sum += w.weight;
        for (std::size_t k = 0; k < 3; ++k) {
            const bool has = k < top.size();
            binding.guides[3 * i + k] = std::int32_t(has ? top[k].guide : top.front().guide);
            binding.weights[3 * i + k] = has && sum > 0.0 ? float(top[k].weight / sum) : 0.0f;
        }
    }
}

} // namespace

const ParamTable<PointInterpolationParams>& pointInterpolationParameters()
{
    using P = PointInterpolationParams;
    static const ParamTable<P> table = [] {
        ParamTable<P> t;
        auto grouping = makeParam<P>("grouping", "points: shape (a new hair blends only guides shaped like its nearest one: partings and layers stay apart) or none", "",
                                     named<P>([](P& p) -> GuideGrouping& { return p.grouping; }, guideGroupingName, guideGroupingFromName));
        grouping.choices = {"shape", "none"};
        t.push_back(grouping);
        auto likeness = makeParam<P>("likeness", "grouping shape: the shape distance, a fraction of the guide length, at which a guide stops taking part", "",
                                     member<P>([](P& p) -> double& { return p.likeness; }));
        likeness.min = 0.0;
        likeness.aboveMin = true;
        t.push_back(likeness);
        return t;
    }();
    return table;
}

const char* guideGroupingName(GuideGrouping grouping) { return grouping == GuideGrouping::Shape ? "shape" : "none"; }

GuideGrouping guideGroupingFromName(const std::string& name)
{
    if (name == "shape") return GuideGrouping::Shape;
    if (name == "none") return GuideGrouping::None;
    throw ParamError<ValueError>({paramName(pointInterpolationParameters(), "grouping"), " '" + name + "' is not one of shape, none"});
}

double likenessDistance(const Vec3f* a, std::size_t na, const Vec3f* b, std::size_t nb)
{
    if (na == 0 || nb == 0) return 0.0;
    return signatureDistance(likenessSignature(a, na), polylineLength(a, na), likenessSignature(b, nb), polylineLength(b, nb));
}

StrandSet interpolatePoints(const StrandSet& guides, const InterpolationRoots& roots, const PointInterpolationParams& params,
                            const GuideContext& context, bool threaded, openvdb::util::NullInterrupter* interrupter,
                            std::size_t* groupsOut, std::vector<std::uint32_t>* rootGroupsOut, GuideBinding* bindingOut)
{
    checkArguments(guides.numStrands(), roots.positions.size(), roots, params, context);
    const bool surface = context.frames == FrameRule::Surface;
    const GuideTable table = tabulateGuides(guides);
    checkRoots(roots, table.maxCount, params.maxVertices);
    GuideGroups gg = groupGuides(table.roots, roots, context);
    const std::vector<Vec3d> gn = guideNormals(context, surface, roots, table.roots);

    StrandSet out;
    const std::vector<std::vector<GuideWeight>> weights = weighRoots(guides, roots, table, gg, params, threaded, out);
    blendPoints(guides, roots, table, weights, gn, surface, threaded, interrupter, out);
    if (bindingOut) bindHeaviestGuides(weights, *bindingOut);
    if (groupsOut) *groupsOut = gg.groups.size();
    if (rootGroupsOut) *rootGroupsOut = std::move(gg.rootGroup);
    return out;
}

} // namespace vdbhair
