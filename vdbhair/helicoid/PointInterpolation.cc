#include "PointInterpolation.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/Format.h>
#include <vdbhair/Progress.h>
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

/// The smallest rotation taking unit @a a to unit @a b (OpenVDB's; apply it with transform(): OpenVDB matrices act on row vectors).
openvdb::math::Mat3d rotationBetween(const Vec3d& a, const Vec3d& b)
{
    return openvdb::math::rotation<openvdb::math::Mat3d>(a, b);
}

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

} // namespace

const char* guideGroupingName(GuideGrouping grouping) { return grouping == GuideGrouping::Shape ? "shape" : "none"; }

GuideGrouping guideGroupingFromName(const std::string& name)
{
    if (name == "shape") return GuideGrouping::Shape;
    if (name == "none") return GuideGrouping::None;
    throw ValueError("grouping '" + name + "' is not one of shape, none");
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
    // Arguments, before any work.
    const std::size_t G = guides.numStrands(), R = roots.positions.size();
    if (G == 0) throw ValueError("no guides: interpolation needs at least one guide");
    if (R == 0) throw ValueError("no roots: interpolation needs at least one root");
    if (params.neighbors < 1) throw ValueError("neighbors " + std::to_string(params.neighbors) + ": must be at least 1");
    if (!(params.likeness > 0.0) || !std::isfinite(params.likeness)) {
        throw ValueError("likeness " + formatNumber(params.likeness) + ": must be a positive fraction of the guide length");
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
    const bool surface = context.frames == FrameRule::Surface;
    if (surface && roots.normals.empty()) throw ValueError("surface frames need root normals; the roots have none");

    // Guides: arc lengths (double), roots, likeness signatures, and checks.
    std::vector<std::vector<double>> arc(G);
    std::vector<Vec3d> guideRoots(G);
    std::vector<std::array<Vec3f, kLikenessSamples>> signature(G);
    std::size_t maxCount = 0;
    for (std::size_t g = 0; g < G; ++g) {
        const std::size_t n = guides.size(g), b = guides.begin(g);
        if (n < 2) throw ValueError("guide " + std::to_string(g) + ": has " + std::to_string(n) + " vertex; a guide needs at least 2");
        arc[g].resize(n);
        arc[g][0] = 0.0;
        for (std::size_t k = 0; k < n; ++k) {
            const Vec3f& p = guides.positions[b + k];
            if (!std::isfinite(p.x()) || !std::isfinite(p.y()) || !std::isfinite(p.z())) {
                throw ValueError("guide " + std::to_string(g) + ": vertex " + std::to_string(k) + " is not finite");
            }
            if (k > 0) arc[g][k] = arc[g][k - 1] + double((p - guides.positions[b + k - 1]).length());
        }
        if (!(arc[g].back() > 0.0)) throw ValueError("guide " + std::to_string(g) + ": zero length: a guide must have a positive length");
        guideRoots[g] = toD(guides.positions[b]);
        signature[g] = likenessSignature(guides.positions.data() + b, n);
        maxCount = std::max(maxCount, n);
    }
    const double estimate = double(R) * double(maxCount);
    if (estimate > double(params.maxVertices)) {
        throw LimitError(std::to_string(R) + " strands would hold up to " + formatNumber(estimate) + " vertices, more than the cap of " +
                         std::to_string(params.maxVertices) + " (fewer roots)");
    }
    for (std::size_t i = 0; i < R; ++i) {
        const Vec3d& p = roots.positions[i];
        if (!std::isfinite(p.x()) || !std::isfinite(p.y()) || !std::isfinite(p.z())) throw ValueError("root " + std::to_string(i) + " is not finite");
    }

    // Groups: a k-d tree of each group's guide roots. Ids in ascending order.
    std::map<std::int32_t, std::size_t> groupIndex;
    for (std::size_t g = 0; g < G; ++g) groupIndex.emplace(context.groups.empty() ? 0 : context.groups[g], 0);
    std::size_t M = 0;
    for (auto& e : groupIndex) e.second = M++;
    std::vector<GroupLocator> groups(M);
    std::vector<std::uint32_t> guideGroup(G, 0);
    for (std::size_t g = 0; g < G; ++g) {
        guideGroup[g] = std::uint32_t(groupIndex.at(context.groups.empty() ? 0 : context.groups[g]));
        groups[guideGroup[g]].members.push_back(std::uint32_t(g));
    }
    for (GroupLocator& gl : groups) {
        std::vector<Vec3d> r;
        for (std::uint32_t g : gl.members) r.push_back(guideRoots[g]);
        gl.locator = std::make_unique<GuideLocator>(std::move(r));
    }
    std::vector<std::uint32_t> rootGroup(R, 0);
    for (std::size_t i = 0; i < roots.groups.size(); ++i) {
        const auto it = groupIndex.find(roots.groups[i]);
        if (it == groupIndex.end()) {
            throw ValueError("root " + std::to_string(i) + ": group " + std::to_string(roots.groups[i]) + " has no guides; every root group needs at least one");
        }
        rootGroup[i] = std::uint32_t(it->second);
    }
    std::unique_ptr<GuideLocator> all;
    if (roots.groups.empty() && M > 1) all = std::make_unique<GuideLocator>(guideRoots);

    // Guide normals (surface frames): given, or those of the roots nearest the guides.
    std::vector<Vec3d> gn = context.normals;
    if (surface && gn.empty()) {
        const GuideLocator near(roots.positions);
        for (const Vec3d& r : guideRoots) gn.push_back(roots.normals[near.nearest(r)]);
    }
    for (Vec3d& n : gn) {
        if (!(n.length() > 0.0) || !std::isfinite(n.length())) throw ValueError("a guide normal is zero or not finite");
        n.normalize();
    }
    // 1-3: weights and vertex counts first (offsets need every count), then the points.
    std::vector<std::vector<GuideWeight>> weights(R);
    StrandSet out;
    out.offsets.assign(R + 1, 0);
    auto weigh = [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
            const Vec3d& x = roots.positions[i];
            const std::uint32_t group = roots.groups.empty() ? (all ? guideGroup[all->nearest(x)] : 0u) : rootGroup[i];
            rootGroup[i] = group;
            const GroupLocator& gl = groups[group];
            std::vector<GuideWeight>& ws = weights[i];
            gl.locator->fadedWeights(x, params.neighbors, ws);
            for (GuideWeight& w : ws) w.guide = gl.members[w.guide];
            if (params.grouping == GuideGrouping::Shape && ws.size() > 1) {
                const std::uint32_t nearest = ws.front().guide;  // fadedWeights() lists the nearest first
                const double ln = arc[nearest].back();
                double sum = 0.0;
                for (GuideWeight& w : ws) {
                    const double u = signatureDistance(signature[nearest], ln, signature[w.guide], arc[w.guide].back()) / params.likeness;
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
    out.positions.resize(out.offsets.back());

    // 4: the points.
    ProgressCounter progress(interrupter, "blending guide points", R, "strands");
    auto blend = [&](const tbb::blocked_range<std::size_t>& r) {
        if (progress.stopped()) return;
        std::vector<Vec3d> acc;
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
            const std::size_t n = out.size(i);
            acc.assign(n, Vec3d(0.0));
            const Vec3d rootNormal = surface ? roots.normals[i].unit() : Vec3d(0.0);
            for (const GuideWeight& w : weights[i]) {
                const std::vector<double>& s = arc[w.guide];
                const Vec3f* p = guides.positions.data() + guides.begin(w.guide);
                const std::size_t m = s.size();
                openvdb::math::Mat3d rot = openvdb::math::Mat3d::identity();
                if (surface) rot = rotationBetween(gn[w.guide], rootNormal);
                std::size_t seg = 0;
                if (m == n) {
                    // The same count: the guide's own vertices (a root on a guide's root is that guide).
                    for (std::size_t k = 0; k < n; ++k) {
                        Vec3d offset = toD(p[k]) - guideRoots[w.guide];
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
                    Vec3d offset = a + (b - a) * f - guideRoots[w.guide];
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

    if (bindingOut) {
        bindingOut->guides.assign(3 * R, 0);
        bindingOut->weights.assign(3 * R, 0.0f);
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
                bindingOut->guides[3 * i + k] = std::int32_t(has ? top[k].guide : top.front().guide);
                bindingOut->weights[3 * i + k] = has && sum > 0.0 ? float(top[k].weight / sum) : 0.0f;
            }
        }
    }
    if (groupsOut) *groupsOut = M;
    if (rootGroupsOut) *rootGroupsOut = std::move(rootGroup);
    return out;
}

} // namespace vdbhair
