#include "PointInterpolation.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/Format.h>
#include <vdbhair/Progress.h>
#include <vdbhair/helicoid/ShepardWeights.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

namespace vdbhair {

namespace {

/// The smallest rotation taking unit @a a to unit @a b, applied to @a v (Rodrigues).
Vec3d rotateBetween(const Vec3d& a, const Vec3d& b, const Vec3d& v)
{
    const Vec3d axis = a.cross(b);
    const double s = axis.length(), c = a.dot(b);
    if (s < 1e-12) {
        if (c > 0.0) return v;
        // Opposite normals: a half turn about any axis perpendicular to a.
        Vec3d p = std::abs(a.x()) < 0.9 ? Vec3d(1.0, 0.0, 0.0) : Vec3d(0.0, 1.0, 0.0);
        p = (p - a * a.dot(p)).unit();
        return 2.0 * p * p.dot(v) - v;
    }
    const Vec3d k = axis / s;
    return v * c + k.cross(v) * s + k * (k.dot(v) * (1.0 - c));
}

} // namespace

StrandSet interpolatePoints(const StrandSet& guides, const InterpolationRoots& roots, const PointInterpolationParams& params,
                            const std::vector<Vec3d>& guideNormals, bool threaded, openvdb::util::NullInterrupter* interrupter)
{
    const std::size_t G = guides.numStrands(), R = roots.positions.size();
    if (G == 0) throw ValueError("no guides: interpolation needs at least one guide");
    if (R == 0) throw ValueError("no roots: interpolation needs at least one root");
    if (params.neighbors < 1) throw ValueError("neighbors " + std::to_string(params.neighbors) + ": must be at least 1");
    if (!roots.normals.empty() && roots.normals.size() != R) {
        throw ValueError(std::to_string(roots.normals.size()) + " root normals for " + std::to_string(R) + " roots");
    }
    if (!guideNormals.empty() && guideNormals.size() != G) {
        throw ValueError(std::to_string(guideNormals.size()) + " guide normals for " + std::to_string(G) + " guides");
    }
    // Guides: arc lengths (double), roots, and checks.
    std::vector<std::vector<double>> arc(G);
    std::vector<Vec3d> guideRoots(G);
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
        const Vec3f& r = guides.positions[b];
        guideRoots[g] = Vec3d(r.x(), r.y(), r.z());
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
    const GuideLocator locator(guideRoots);
    std::vector<Vec3d> gn = guideNormals;
    const bool surface = !roots.normals.empty();
    if (surface && gn.empty()) {
        const GuideLocator near(roots.positions);
        for (const Vec3d& r : guideRoots) gn.push_back(roots.normals[near.nearest(r)]);
    }
    for (Vec3d& n : gn) {
        if (!(n.length() > 0.0)) throw ValueError("a guide normal is zero");
        n.normalize();
    }

    // Weights and vertex counts first (offsets need every count), then the points.
    std::vector<std::vector<GuideWeight>> weights(R);
    StrandSet out;
    out.offsets.assign(R + 1, 0);
    auto weigh = [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
            locator.fadedWeights(roots.positions[i], params.neighbors, weights[i]);
            double n = 0.0;
            for (const GuideWeight& w : weights[i]) n += w.weight * double(guides.size(w.guide));
            out.offsets[i + 1] = std::uint32_t(std::max<long>(2, std::lround(n)));
        }
    };
    if (threaded) tbb::parallel_for(tbb::blocked_range<std::size_t>(0, R, 1024), weigh);
    else weigh(tbb::blocked_range<std::size_t>(0, R));
    for (std::size_t i = 0; i < R; ++i) out.offsets[i + 1] += out.offsets[i];
    out.positions.resize(out.offsets.back());

    ProgressCounter progress(interrupter, "blending guide points", R, "strands");
    auto blend = [&](const tbb::blocked_range<std::size_t>& r) {
        if (progress.stopped()) return;
        std::vector<Vec3d> acc;
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
            const std::size_t n = out.size(i);
            acc.assign(n, Vec3d(0.0));
            Vec3d rootNormal(0.0);
            if (surface) rootNormal = roots.normals[i].unit();
            for (const GuideWeight& w : weights[i]) {
                const std::vector<double>& s = arc[w.guide];
                const Vec3f* p = guides.positions.data() + guides.begin(w.guide);
                const std::size_t m = s.size();
                std::size_t seg = 0;
                for (std::size_t k = 0; k < n; ++k) {
                    // Resample by arc length: the point at k / (n - 1) of the guide's length.
                    const double target = s.back() * double(k) / double(n - 1);
                    while (seg + 2 < m && s[seg + 1] < target) ++seg;
                    const double len = s[seg + 1] - s[seg];
                    const double f = len > 0.0 ? std::clamp((target - s[seg]) / len, 0.0, 1.0) : 0.0;
                    const Vec3d a(p[seg].x(), p[seg].y(), p[seg].z()), b(p[seg + 1].x(), p[seg + 1].y(), p[seg + 1].z());
                    Vec3d offset = a + (b - a) * f - guideRoots[w.guide];
                    if (k == n - 1) offset = Vec3d(p[m - 1].x(), p[m - 1].y(), p[m - 1].z()) - guideRoots[w.guide];
                    if (surface) offset = rotateBetween(gn[w.guide], rootNormal, offset);
                    acc[k] += w.weight * offset;
                }
            }
            Vec3f* dst = out.positions.data() + out.begin(i);
            for (std::size_t k = 0; k < n; ++k) {
                const Vec3d q = roots.positions[i] + acc[k];
                dst[k] = Vec3f(float(q.x()), float(q.y()), float(q.z()));
            }
        }
        progress.add(r.size());
    };
    if (threaded) tbb::parallel_for(tbb::blocked_range<std::size_t>(0, R, 256), blend);
    else blend(tbb::blocked_range<std::size_t>(0, R));
    if (progress.stopped()) throw InterruptedError("interpolatePoints: interrupted");
    return out;
}

StrandSet interpolatePoints(const Scene& guides, const InterpolationRoots& roots, const PointInterpolationParams& params,
                            const std::vector<Vec3d>& guideNormals, bool threaded, openvdb::util::NullInterrupter* interrupter)
{
    Scene bare = guides;
    for (SceneGuide& g : bare.guides) g.wisp.reset();
    const StrandSet guideStrands = growScene(bare, {}, threaded, interrupter);
    return interpolatePoints(guideStrands, roots, params, guideNormals, threaded, interrupter);
}

} // namespace vdbhair
