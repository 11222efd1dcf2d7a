#include "HeadCollision.h"

#include <vdbhair/Exceptions.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <string>

namespace vdbhair {

namespace {

Vec3d toD(const Vec3f& v) { return Vec3d(v.x(), v.y(), v.z()); }

/// The state of one strand while it is pushed out (reused per thread).
struct StrandWork
{
    std::vector<Vec3d> p, disp;
    std::vector<double> seg, arc;
    std::vector<char> bent;
};

/// One sweep from root to tip: each segment keeps its direction and length from the (already
/// placed) vertex before it, so below a contact the strand keeps its shape, moved out; where a
/// vertex is deeper than its floor, its segment turns towards the head's normal by the least angle
/// that brings it to its floor (bisection). Lengths are kept exactly and nothing folds: a strand
/// that runs into the head follows its surface until its own direction leads away. Marks the
/// vertices within @a width of a turn in w.bent; @return whether anything turned.
bool sweep(std::size_t n, const std::function<double(std::size_t)>& floorAt, HeadObstacle::Probe& probe, double width, StrandWork& w)
{
    bool turned = false;
    Vec3d before = w.p[0];  // vertex k - 1 before this sweep placed it
    for (std::size_t k = 1; k < n; ++k) {
        const Vec3d a = w.p[k - 1];
        const Vec3d d = w.p[k] - before;
        before = w.p[k];
        const double l = w.seg[k], dl = d.length();
        if (!(l > 0.0) || !(dl > 0.0)) {
            w.p[k] = a + (dl > 0.0 ? d / dl : Vec3d(0.0)) * l;
            continue;
        }
        const Vec3d dHat = d / dl;
        w.p[k] = a + dHat * l;
        Vec3d nrm;
        const double floor = floorAt(k), d0 = probe.distance(w.p[k], nrm);
        if (!(d0 < floor)) continue;
        if (nrm.lengthSqr() == 0.0) probe.distance(a, nrm);
        Vec3d t = nrm - dHat * dHat.dot(nrm);
        if (t.lengthSqr() < 1e-20) {  // straight in or straight out: any perpendicular
            t = std::abs(dHat.x()) < 0.9 ? Vec3d(1.0, 0.0, 0.0) : Vec3d(0.0, 1.0, 0.0);
            t -= dHat * dHat.dot(t);
        }
        t.normalize();
        // The least angle towards t that lifts vertex k out, up to a half turn (to a hair past its
        // floor, so the float vertex does not round back in): bracketed from the first-order
        // estimate d(θ) ≈ d(0) + l θ (n · t), then bisected to a 64th of the bracket.
        const double target = floor + 1e-4 * l;
        auto at = [&](double theta) { return a + (dHat * std::cos(theta) + t * std::sin(theta)) * l; };
        const double slope = l * nrm.dot(t);
        double lo = 0.0, hi = M_PI;
        bool found = false;
        const double guess = slope > 0.0 ? 1.25 * (target - d0) / slope : 0.0;
        if (guess > 0.0 && guess < M_PI && !(probe.distance(at(guess)) < target)) {
            hi = guess;
            found = true;
        } else {
            if (guess > 0.0 && guess < M_PI) lo = guess;
            for (double angle : {M_PI / 16.0, M_PI / 8.0, M_PI / 4.0, M_PI / 2.0, 3.0 * M_PI / 4.0, M_PI}) {
                if (angle <= lo) continue;
                if (!(probe.distance(at(angle)) < target)) {
                    hi = angle;
                    found = true;
                    break;
                }
                lo = angle;
            }
        }
        if (!found) continue;  // no turn lifts it (the vertex before is deep itself): the last pass pushes it
        for (int it = 0; it < 6; ++it) {
            const double mid = 0.5 * (lo + hi);
            if (probe.distance(at(mid)) < target) lo = mid;
            else hi = mid;
        }
        w.p[k] = at(hi);
        for (std::size_t j = k; j >= 1 && w.arc[k] - w.arc[j] <= width; --j) w.bent[j] = 1;
        for (std::size_t j = k + 1; j < n && w.arc[j] - w.arc[k] <= width; ++j) w.bent[j] = 1;
        turned = true;
    }
    return turned;
}

/// Resolve one strand of @a n vertices at @a pos; @return whether it moved, and add to @a tooDeep.
bool resolveStrand(Vec3f* pos, std::size_t n, const float* allowed, HeadObstacle::Probe& probe, const HeadCollisionParams& params,
                   StrandWork& w, std::size_t& tooDeep)
{
    if (n < 2) return false;
    const std::function<double(std::size_t)> floorAt = [&](std::size_t k) { return allowed ? -double(allowed[k]) : 0.0; };
    // A quick test first: most strands never touch the head.
    bool any = false;
    for (std::size_t k = 1; k < n && !any; ++k) any = probe.distance(toD(pos[k])) < floorAt(k);
    if (!any) return false;

    w.p.resize(n);
    w.seg.assign(n, 0.0);
    w.arc.assign(n, 0.0);
    w.bent.assign(n, 0);
    for (std::size_t k = 0; k < n; ++k) w.p[k] = toD(pos[k]);
    for (std::size_t k = 1; k < n; ++k) {
        w.seg[k] = (w.p[k] - w.p[k - 1]).length();
        w.arc[k] = w.arc[k - 1] + w.seg[k];
    }
    const double width = params.spread * w.arc[n - 1];
    // Sweep; relax the bends over the stretch around them (Laplacian steps; the root stays, the
    // next sweep restores the lengths), which may dip a vertex back in; sweep again.
    for (int pass = 0; pass < params.passes; ++pass) {
        if (!sweep(n, floorAt, probe, width, w)) break;
        if (pass + 1 == params.passes) break;  // end on a sweep
        for (int it = 0; it < params.smoothing; ++it) {
            w.disp.assign(n, Vec3d(0.0));
            for (std::size_t k = 1; k + 1 < n; ++k) {
                if (w.bent[k]) w.disp[k] = 0.25 * (w.p[k - 1] + w.p[k + 1]) - 0.5 * w.p[k];
            }
            for (std::size_t k = 1; k + 1 < n; ++k) w.p[k] += w.disp[k];
        }
    }
    // What is still too deep, vertex by vertex.
    for (std::size_t k = 1; k < n; ++k) {
        const double floor = floorAt(k);
        pos[k] = Vec3f(float(w.p[k].x()), float(w.p[k].y()), float(w.p[k].z()));
        if (!(probe.distance(toD(pos[k])) < floor)) continue;
        probe.pushOut(w.p[k], floor);
        pos[k] = Vec3f(float(w.p[k].x()), float(w.p[k].y()), float(w.p[k].z()));
        if (probe.distance(toD(pos[k])) < floor) ++tooDeep;
    }
    return true;
}

} // namespace

HeadCollisionStats resolveHeadCollisions(StrandSet& strands, const HeadObstacle& head, const std::vector<float>& allowedDepth,
                                         const HeadCollisionParams& params, bool threaded)
{
    if (!allowedDepth.empty() && allowedDepth.size() != strands.numVertices()) {
        throw ValueError("head collision: " + std::to_string(allowedDepth.size()) + " allowed depths for " +
                         std::to_string(strands.numVertices()) + " vertices");
    }
    for (float a : allowedDepth) {
        if (!(a >= 0.f) || !std::isfinite(a)) throw ValueError("head collision: an allowed depth of " + std::to_string(a) + ": must be finite and non-negative");
    }
    if (!(params.spread >= 0.0) || !std::isfinite(params.spread)) throw ValueError("head collision: spread must be a finite fraction >= 0");
    if (params.passes < 0 || params.smoothing < 0) throw ValueError("head collision: passes and smoothing must be >= 0");
    HeadCollisionStats stats;
    if (head.empty() || strands.empty()) return stats;
    const std::size_t S = strands.numStrands();
    std::vector<char> moved(S, 0);
    std::vector<std::size_t> deep(S, 0);
    auto run = [&](const tbb::blocked_range<std::size_t>& r) {
        HeadObstacle::Probe probe(head);
        StrandWork w;
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
            const std::size_t b = strands.begin(i);
            moved[i] = resolveStrand(strands.positions.data() + b, strands.size(i), allowedDepth.empty() ? nullptr : allowedDepth.data() + b,
                                     probe, params, w, deep[i]);
        }
    };
    if (threaded) tbb::parallel_for(tbb::blocked_range<std::size_t>(0, S, 256), run);
    else run(tbb::blocked_range<std::size_t>(0, S));
    for (std::size_t i = 0; i < S; ++i) {
        stats.strandsMoved += std::size_t(moved[i]);
        stats.verticesTooDeep += deep[i];
    }
    return stats;
}

std::vector<float> rootDepthAllowance(const StrandSet& strands, const HeadObstacle& head, bool threaded)
{
    std::vector<float> allowed(strands.numVertices(), 0.f);
    if (head.empty()) return allowed;
    auto run = [&](const tbb::blocked_range<std::size_t>& r) {
        HeadObstacle::Probe probe(head);
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
            if (strands.size(i) == 0) continue;
            const float d = float(std::max(0.0, -probe.distance(toD(strands.root(i)))));
            std::fill(allowed.begin() + std::ptrdiff_t(strands.begin(i)), allowed.begin() + std::ptrdiff_t(strands.begin(i) + strands.size(i)), d);
        }
    };
    if (threaded) tbb::parallel_for(tbb::blocked_range<std::size_t>(0, strands.numStrands(), 1024), run);
    else run(tbb::blocked_range<std::size_t>(0, strands.numStrands()));
    return allowed;
}

double headTolerance(const HeadObstacle& head)
{
    if (head.empty() || head.isSphere()) return 0.0;
    return 0.5 * head.voxelSize();
}

std::size_t countStrandsEnteringHead(const StrandSet& strands, const HeadObstacle& head, double tolerance, bool threaded)
{
    if (head.empty()) return 0;
    auto count = [&](const tbb::blocked_range<std::size_t>& r, std::size_t acc) {
        HeadObstacle::Probe probe(head);
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
            const std::size_t n = strands.size(i), b = strands.begin(i);
            if (n < 2) continue;
            const double root = probe.distance(toD(strands.positions[b]));
            for (std::size_t k = 1; k < n; ++k) {
                const double d = probe.distance(toD(strands.positions[b + k]));
                if (d < -tolerance && d < root - tolerance) {
                    ++acc;
                    break;
                }
            }
        }
        return acc;
    };
    const tbb::blocked_range<std::size_t> all(0, strands.numStrands(), 256);
    if (!threaded) return count(all, 0);
    return tbb::parallel_reduce(all, std::size_t(0), count, [](std::size_t a, std::size_t b) { return a + b; });
}

} // namespace vdbhair
