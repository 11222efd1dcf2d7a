#include "HeadCollision.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/Rotation.h>
#include <vdbhair/strands/PointCloud.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <string>

namespace vdbhair {

namespace {

Vec3d toD(const Vec3f& v) { return Vec3d(v.x(), v.y(), v.z()); }

/// The state of one strand while it is pushed out (reused per thread).
struct StrandWork
{
    std::vector<Vec3d> p, c;  ///< the strand, and as it was given
    std::vector<Vec3d> r;     ///< the strand before this pass's sweep (accumulated passes)
    /// Each edge's turn from the given strand (a rotation vector: axis times angle), its smoothed
    /// copy and prefix sums (smoothTurns())
    std::vector<Vec3d> turn, smooth, sum;
    std::vector<std::size_t> turned;  ///< prefix counts of the edges with a turn
    std::vector<double> seg, arc;
    std::vector<Vec3d> best;  ///< the swept strand with the smallest largest turn between two edges so far
    /// The Gaussian's normalized weights of edge k over edges kernelLo[k] .., stored from
    /// kernelAt[k] to kernelAt[k + 1] (built once a strand; empty until needed)
    std::vector<double> weight;
    std::vector<std::size_t> kernelAt, kernelLo;
};

/// How deep vertex k may be (a floor on its signed distance): -allowed[k] (0 without an allowance),
/// under HeadDepthRule::Rising also no lower than the shallowest vertex placed before it (clamped at 0).
struct DepthFloor
{
    const float* allowed;
    bool rising;
    double shallowest = -std::numeric_limits<double>::infinity();  ///< largest signed distance of the vertices placed so far

    double at(std::size_t k) const
    {
        const double f = allowed ? -double(allowed[k]) : 0.0;
        return rising ? std::max(f, std::min(0.0, shallowest)) : f;
    }
    void placed(double d) { shallowest = std::max(shallowest, d); }
};

const double kKinkCosine = std::cos(kKinkDegrees * M_PI / 180.0);

/// Directions spread evenly over the sphere (a Fibonacci lattice): the search of last resort for
/// an edge that no turn in one plane lifts out.
constexpr int kSphereDirections = 128;
const std::vector<Vec3d>& sphereDirections()
{
    static const std::vector<Vec3d> dirs = [] {
        std::vector<Vec3d> d(kSphereDirections);
        const double golden = M_PI * (3.0 - std::sqrt(5.0));
        for (int j = 0; j < kSphereDirections; ++j) {
            const double z = 1.0 - (2.0 * j + 1.0) / kSphereDirections, r = std::sqrt(1.0 - z * z);
            d[std::size_t(j)] = Vec3d(r * std::cos(golden * j), r * std::sin(golden * j), z);
        }
        return d;
    }();
    return dirs;
}

/// An edge of length @a l from @a a along the unit @a from turned towards the unit @a t
/// (perpendicular to it) by the least angle, up to @a maxAngle, that brings its end to @a target
/// or above: bracketed from the first-order estimate d(θ) ≈ d(0) + l θ (n · t) when @a slope
/// (l n · t) is positive, else by the angles π/32, π/16, π/8 .. @a maxAngle; then bisected to a
/// 64th of the bracket.
struct Lift
{
    bool found = false;
    double angle = 0.0;  ///< from @a from
    double distance = 0.0;  ///< the end's signed distance
    Vec3d end;
};
Lift liftEdge(HeadObstacle::Probe& probe, const Vec3d& a, const Vec3d& from, const Vec3d& t, double l, double target, double d0,
              double slope, double maxAngle)
{
    auto at = [&](double theta) { return a + (from * std::cos(theta) + t * std::sin(theta)) * l; };
    Lift r;
    double lo = 0.0, hi = maxAngle;
    const double guess = slope > 0.0 ? 1.25 * (target - d0) / slope : 0.0;
    if (guess > 0.0 && guess < maxAngle && !((r.distance = probe.distance(at(guess))) < target)) {
        hi = guess;
        r.found = true;
    } else {
        if (guess > 0.0 && guess < maxAngle) lo = guess;
        for (double angle : {M_PI / 32.0, M_PI / 16.0, M_PI / 8.0, M_PI / 4.0, M_PI / 2.0, 3.0 * M_PI / 4.0, M_PI}) {
            angle = std::min(angle, maxAngle);
            if (angle <= lo) continue;
            if (!((r.distance = probe.distance(at(angle))) < target)) {
                hi = angle;
                r.found = true;
                break;
            }
            lo = angle;
        }
    }
    if (!r.found) return r;
    for (int it = 0; it < 6; ++it) {
        const double mid = 0.5 * (lo + hi), dm = probe.distance(at(mid));
        if (dm < target) lo = mid;
        else {
            hi = mid;
            r.distance = dm;
        }
    }
    r.angle = hi;
    r.end = at(hi);
    return r;
}

/// The unit part of @a v perpendicular to the unit @a u, or any unit perpendicular where there is none.
Vec3d perpendicular(const Vec3d& v, const Vec3d& u)
{
    Vec3d t = v - u * u.dot(v);
    if (t.lengthSqr() < 1e-20) {
        t = std::abs(u.x()) < 0.9 ? Vec3d(1.0, 0.0, 0.0) : Vec3d(0.0, 1.0, 0.0);
        t -= u * u.dot(t);
    }
    return t.unit();
}

/// One sweep from root to tip: each segment keeps its direction and length from the (already
/// placed) vertex before it, so below a contact the strand keeps its shape, moved out; where a
/// vertex is deeper than its floor, its segment turns towards the head's normal by the least angle
/// that brings it to its floor (bisection). Lengths are kept exactly and nothing folds: a strand
/// that runs into the head follows its surface until its own direction leads away. @return the
/// largest turn it made (radians; 0: none).
double sweep(std::size_t n, DepthFloor floor, HeadObstacle::Probe& probe, StrandWork& w)
{
    double turned = 0.0;
    Vec3d before = w.p[0];  // vertex k - 1 before this sweep placed it
    floor.placed(probe.distance(w.p[0]));
    for (std::size_t k = 1; k < n; ++k) {
        const Vec3d a = w.p[k - 1];
        const Vec3d d = w.p[k] - before;
        before = w.p[k];
        const double l = w.seg[k], dl = d.length();
        if (!(l > 0.0) || !(dl > 0.0)) {
            w.p[k] = a + (dl > 0.0 ? d / dl : Vec3d(0.0)) * l;
            if (floor.rising) floor.placed(probe.distance(w.p[k]));
            continue;
        }
        const Vec3d dHat = d / dl;
        w.p[k] = a + dHat * l;
        Vec3d nrm;
        const double fl = floor.at(k), d0 = probe.distance(w.p[k], nrm);
        if (!(d0 < fl)) {
            floor.placed(d0);
            continue;
        }
        if (nrm.lengthSqr() == 0.0) probe.distance(a, nrm);
        // The edge before, placed (none at the root's edge).
        Vec3d prev(0.0);
        if (k >= 2) {
            const Vec3d e = w.p[k - 1] - w.p[k - 2];
            if (e.lengthSqr() > 0.0) prev = e.unit();
        }
        // Turned towards the normal alone, a strand aimed at the head nearly head-on has no one way
        // to slide: where the normals of consecutive deep vertices tilt opposite ways (by Sintel's
        // ear), it zigzagged between two points, 150-180 degrees between its edges. It also turns
        // the way its last placed edge went; both parts weigh by their sine to dHat, so an oblique
        // contact still turns towards the normal, and a head-on one keeps sliding on.
        const Vec3d t = perpendicular(nrm - dHat * dHat.dot(nrm) + (prev - dHat * dHat.dot(prev)), dHat);
        // The least angle towards t that lifts vertex k out, up to a half turn (to a hair past its
        // floor, so the float vertex does not round back in).
        const double target = fl + 1e-4 * l;
        Lift lift = liftEdge(probe, a, dHat, t, l, target, d0, l * nrm.dot(t), M_PI);
        if (!lift.found) {
            // No turn in that plane lifts it: where the level set is thin (HairNet's ear, 1.5 of
            // its voxels across) the normals of two points an edge apart point opposite ways, and
            // a strand left there went on inside, to be pushed out vertex by vertex into a fold
            // (turns of 165-178 degrees between edges). The least turn in any direction that lifts
            // it, else the direction that rises most (the next edge lifts the rest).
            double least = 4.0, highest = -std::numeric_limits<double>::infinity();
            Vec3d toward = dHat, rise = dHat;
            for (const Vec3d& u : sphereDirections()) {
                const double du = probe.distance(a + u * l);
                if (du > highest) {
                    highest = du;
                    rise = u;
                }
                const double angle = std::acos(std::clamp(u.dot(dHat), -1.0, 1.0));
                if (!(du < target) && angle < least) {
                    least = angle;
                    toward = u;
                }
            }
            if (least < 4.0) lift = liftEdge(probe, a, dHat, perpendicular(toward, dHat), l, target, d0, 0.0, least);
            if (!lift.found) {
                lift.end = a + rise * l;
                lift.distance = highest;
                lift.angle = std::acos(std::clamp(rise.dot(dHat), -1.0, 1.0));
            }
        }
        // A contact nearly head-on (a strand pressed into the head: dHat along the inward normal)
        // turns its edge by 90 degrees or more from its own direction whichever way it turns, and
        // as much from the edge before: a kink at every such vertex, which the passes' smoothing
        // could not spread (HairNet's fringe pressed into its face turned 100-150 degrees at every
        // sweep). Where the edge would bend a kink from the edge before, it turns instead from the
        // edge before's direction towards the normal there, if that bends it less: it slides on
        // along the surface the way it was going. Not for new hair (HeadDepthRule::Rising), which
        // grows out of the scalp rather than being pressed into it: there the edge before rises
        // out of the scalp, and going on along it lifted strands above their roots
        // (`straight.hair` synthesized on its head: 2 % of the strands at the sides, none in
        // the example).
        const double bend = prev == Vec3d(0.0) ? 1.0 : (lift.end - a).dot(prev) / l;
        if (bend < kKinkCosine && !floor.rising) {
            Vec3d np;
            const double dp = probe.distance(a + prev * l, np);
            if (np.lengthSqr() == 0.0) np = nrm;
            const Vec3d tp = perpendicular(np, prev);
            const Lift slide = !(dp < target) ? Lift{true, 0.0, dp, a + prev * l} : liftEdge(probe, a, prev, tp, l, target, dp, l * np.dot(tp), M_PI / 2.0);
            if (slide.found && std::cos(slide.angle) > bend) {
                lift = slide;
                lift.angle = std::acos(std::clamp((slide.end - a).dot(dHat) / l, -1.0, 1.0));
            }
        }
        w.p[k] = lift.end;
        floor.placed(lift.distance);
        turned = std::max(turned, lift.angle);
    }
    return turned;
}

/// @a w.turn (edges 1 .. n-1, each at its midpoint's arc length) smoothed in place by a Gaussian
/// of σ = @a sigma (arc length), each edge's weights normalized over the edges within 3σ. Where that
/// reach spans many edges (a transfer lays curls at up to 1,024 vertices a strand), by three box
/// averages of half width σ instead (Wells 1986, "Efficient synthesis of Gaussian filters by
/// cascaded uniform filters": prefix sums, linear in the vertices whatever the reach); on coarse
/// strands (16 vertices) a box of a few edges is too blunt, and the Gaussian's own weights are kept.
/// In the boxes, the edges past the tip count as turning as the tip's edge does (its turn extended
/// at their spacing): a contact at the tip then spreads back along the strand at full weight,
/// where a window cut at the tip kept most of the turn at the last edges (HairNet's groom combed
/// into its head kept a 46-degree turn between its last two edges of 100; 0 such with the
/// extension). Not on coarse strands: there it keeps more of the tip's own turn (16 vertices:
/// 12 to 15 degrees on the tip-contact test's strands).
void smoothTurns(std::size_t n, double sigma, StrandWork& w)
{
    auto mid = [&](std::size_t k) { return w.arc[k] - 0.5 * w.seg[k]; };
    const double length = w.arc[n - 1];
    // Edges whose reach holds no turn stay unturned: contacts are local.
    w.turned.assign(n + 1, 0);  // w.turned[k + 1] = turned edges among 1 .. k
    for (std::size_t k = 1; k < n; ++k) w.turned[k + 1] = w.turned[k] + (w.turn[k] != Vec3d(0.0));
    if (sigma * double(n - 1) < 3.0 * length) {  // σ under 3 edges
        if (w.kernelAt.empty()) {  // the weights, once a strand
            const double reach = 3.0 * sigma, inv = 1.0 / (2.0 * sigma * sigma);
            w.kernelAt.assign(n + 1, 0);
            w.kernelLo.assign(n, 1);
            w.weight.clear();
            std::size_t first = 1;
            for (std::size_t k = 1; k < n; ++k) {
                while (mid(k) - mid(first) > reach) ++first;
                w.kernelLo[k] = first;
                w.kernelAt[k] = w.weight.size();
                double sum = 0.0;
                for (std::size_t j = first; j < n && mid(j) - mid(k) <= reach; ++j) {
                    w.weight.push_back(std::exp(-(mid(j) - mid(k)) * (mid(j) - mid(k)) * inv));
                    sum += w.weight.back();
                }
                for (std::size_t i = w.kernelAt[k]; i < w.weight.size(); ++i) w.weight[i] /= sum;
            }
            w.kernelAt[n] = w.weight.size();
        }
        for (std::size_t k = 1; k < n; ++k) {
            const std::size_t lo = w.kernelLo[k], len = w.kernelAt[k + 1] - w.kernelAt[k];
            Vec3d acc(0.0);
            if (w.turned[lo + len] != w.turned[lo]) {
                const double* g = w.weight.data() + w.kernelAt[k];
                for (std::size_t i = 0; i < len; ++i) acc += w.turn[lo + i] * g[i];
            }
            w.smooth[k] = acc;
        }
        for (std::size_t k = 1; k < n; ++k) w.turn[k] = w.smooth[k];
        return;
    }
    for (int round = 0; round < 3; ++round) {
        w.sum.assign(n + 1, Vec3d(0.0));  // w.sum[k + 1] = turns of edges 1 .. k
        for (std::size_t k = 1; k < n; ++k) w.sum[k + 1] = w.sum[k] + w.turn[k];
        std::size_t lo = 1, hi = 1;  // edges lo .. hi - 1 are within σ of edge k
        for (std::size_t k = 1; k < n; ++k) {
            while (mid(k) - mid(lo) > sigma) ++lo;
            while (hi < n && mid(hi) - mid(k) <= sigma) ++hi;
            // Edges past the tip within σ of edge k (at the last edge's spacing) turn as it does.
            const double past = hi == n && w.seg[n - 1] > 0.0 ? std::floor((mid(k) + sigma - mid(n - 1)) / w.seg[n - 1]) : 0.0;
            w.smooth[k] = (w.sum[hi] - w.sum[lo] + w.turn[n - 1] * past) / (double(hi - lo) + past);
        }
        for (std::size_t k = 1; k < n; ++k) w.turn[k] = w.smooth[k];
    }
}

/// The largest turn (radians) of a sweep that ends the passes: 5 degrees, a ninth of a kink (45
/// degrees between two edges). Waiting for every turn to vanish took 4 to 12 passes a strand and
/// made the head 3 times slower on 100,000 synthesized strands, for no fewer kinks measured.
constexpr double kSettledTurn = 5.0 * M_PI / 180.0;

/// The cosine of the largest turn between two consecutive edges of the @a n points @a p (1: none).
double leastEdgeCosine(const std::vector<Vec3d>& p, std::size_t n)
{
    double least = 1.0;
    for (std::size_t k = 2; k < n; ++k) {
        const Vec3d a = p[k - 1] - p[k - 2], b = p[k] - p[k - 1];
        const double la = a.length(), lb = b.length();
        if (la > 0.0 && lb > 0.0) least = std::min(least, a.dot(b) / (la * lb));
    }
    return least;
}

/// Resolve one strand of @a n vertices at @a pos; @return whether it moved, and add to @a tooDeep.
bool resolveStrand(Vec3f* pos, std::size_t n, const float* allowed, HeadObstacle::Probe& probe, const HeadCollisionParams& params,
                   StrandWork& w, std::size_t& tooDeep)
{
    if (n < 2) return false;
    const bool rising = params.depthRule == HeadDepthRule::Rising;
    // A quick test first: most strands never touch the head.
    {
        DepthFloor f{allowed, rising};
        f.placed(probe.distance(toD(pos[0])));
        bool any = false;
        for (std::size_t k = 1; k < n && !any; ++k) {
            const double d = probe.distance(toD(pos[k]));
            any = d < f.at(k);
            f.placed(d);
        }
        if (!any) return false;
    }

    w.p.resize(n);
    w.seg.assign(n, 0.0);
    w.arc.assign(n, 0.0);
    for (std::size_t k = 0; k < n; ++k) w.p[k] = toD(pos[k]);
    for (std::size_t k = 1; k < n; ++k) {
        w.seg[k] = (w.p[k] - w.p[k - 1]).length();
        w.arc[k] = w.arc[k - 1] + w.seg[k];
    }
    const DepthFloor floor0{allowed, rising};
    const double sigma = params.spread * w.arc[n - 1];
    // Sweep; smooth the turns it made along the strand (as rotations of the edges, so the strand's
    // own shape rides along and nothing folds) and rebuild it from the root, which may dip a vertex
    // back in, less steeply than before; sweep again.
    w.c = w.p;  // the strand as given
    w.kernelAt.clear();
    // Each sweep leaves the strand out of the head; where the passes do not settle (a strand along
    // the surface whose floor, the input's depth vertex by vertex, rises and falls: HairNet's
    // strands pressed against its head by random strokes turned 30-60 degrees at every pass, their
    // last sweep kinked up to 104 degrees where an earlier one had 25-36), the sweep with the
    // smallest largest turn between two edges is kept.
    double bestCosine = -2.0;
    // Accumulated passes stop as soon as one leaves no new kink (they are there to remove it).
    double enough = 2.0;
    auto passes = [&](bool accumulated) {
        w.p = w.c;
        for (int pass = 0; pass < params.passes; ++pass) {
            if (accumulated) w.r = w.p;
            // A sweep that turned no edge by more than a few degrees leaves no kink: done.
            const double turned = sweep(n, floor0, probe, w);
            if (!(turned > kSettledTurn) && pass == 0 && !accumulated) break;  // settled at once: nothing to compare
            const double cosine = leastEdgeCosine(w.p, n);
            if (cosine > bestCosine) {
                bestCosine = cosine;
                w.best.assign(w.p.begin(), w.p.begin() + std::ptrdiff_t(n));
            }
            if (!(turned > kSettledTurn) || bestCosine >= enough) break;
            if (pass + 1 == params.passes || !(sigma > 0.0)) break;  // end on a sweep
            const std::vector<Vec3d>& from = accumulated ? w.r : w.c;
            w.turn.assign(n, Vec3d(0.0));
            for (std::size_t k = 1; k < n; ++k) {
                const Vec3d a = from[k] - from[k - 1], b = w.p[k] - w.p[k - 1];
                const double la = a.length(), lb = b.length();
                if (la > 0.0 && lb > 0.0) w.turn[k] = rotationVectorBetween(a / la, b / lb);  // none for a half turn: the sweep makes none
            }
            w.smooth.resize(n);
            smoothTurns(n, sigma, w);
            for (std::size_t k = 1; k < n; ++k) w.p[k] = w.p[k - 1] + rotateByVector(from[k] - from[k - 1], w.turn[k]);
        }
    };
    passes(false);
    // The passes rebuild the given strand with the smoothed turns of each sweep, so where a sweep
    // needs a sharp turn the smoothing takes part of it back at every pass, and the sweep makes it
    // again: they need not settle. Where the best of them kinks a strand that was not kinked (over
    // 45 degrees; HairNet's groom pressed into its face, turned 55-70 degrees), passes that each
    // rebuild the strand the sweep was given, with its own turns smoothed, accumulate the turns
    // instead and settle where the sharp turns vanish; the better of the two is kept. Random comb
    // strokes on the six grooms with a head (scripts/comb_strokes.py, seeds 1-4, 192 strokes):
    // 12 strokes leave a new kink with the first scheme alone, 10 with the second alone, 3 with both.
    enough = std::min(kKinkCosine, leastEdgeCosine(w.c, n));
    if (bestCosine > -2.0 && bestCosine < enough) passes(true);
    if (bestCosine > -2.0) std::copy(w.best.begin(), w.best.end(), w.p.begin());
    // What is still too deep, vertex by vertex.
    DepthFloor f = floor0;
    f.placed(probe.distance(w.p[0]));
    for (std::size_t k = 1; k < n; ++k) {
        const double fl = f.at(k);
        pos[k] = Vec3f(float(w.p[k].x()), float(w.p[k].y()), float(w.p[k].z()));
        double d = probe.distance(toD(pos[k]));
        if (d < fl) {
            // Pushed along the normal by about its shortfall. Where the level set is no distance
            // (a coarse head's dilated interior: its gradient a fraction of 1), the Newton steps of
            // pushOut() wandered: a vertex 0.18 too deep in Ruby's head (voxel 2.9) moved 4.3,
            // bending its strand 113 degrees. Such a vertex stays, counted as too deep (pushOut()
            // aims a hair past the floor: a hundredth of the edge covers that).
            const Vec3d at = w.p[k];
            probe.pushOut(w.p[k], fl);
            if ((w.p[k] - at).length() > 3.0 * (fl - d) + 0.01 * w.seg[k]) w.p[k] = at;
            pos[k] = Vec3f(float(w.p[k].x()), float(w.p[k].y()), float(w.p[k].z()));
            d = probe.distance(toD(pos[k]));
            if (d < fl) ++tooDeep;
        }
        f.placed(d);
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
    if (params.passes < 0) throw ValueError("head collision: passes must be >= 0");
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

namespace {

/// The k-d tree over the roots of @a reference (its own copy of them).
struct RootTree
{
    std::vector<Vec3d> roots;
    PointCloud cloud{&roots};
    std::unique_ptr<PointKdTree> tree;

    explicit RootTree(const StrandSet& reference)
    {
        if (reference.numStrands() == 0) throw ValueError("head collision: the reference hair has no strands");
        roots.resize(reference.numStrands());
        for (std::size_t i = 0; i < roots.size(); ++i) roots[i] = toD(reference.size(i) ? reference.root(i) : Vec3f(0.f));
        tree = std::make_unique<PointKdTree>(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(10));
        tree->buildIndex();
    }
    std::uint32_t nearest(const Vec3d& p) const
    {
        const double q[3] = {p.x(), p.y(), p.z()};
        std::uint32_t i = 0;
        double d2 = 0.0;
        tree->knnSearch(q, 1, &i, &d2);
        return i;
    }
};

} // namespace

std::size_t liftRootsToReference(StrandSet& strands, const StrandSet& reference, const HeadObstacle& head, bool threaded,
                                 std::vector<std::uint32_t>* nearestOut)
{
    if (head.empty() || strands.empty()) return 0;
    const RootTree roots(reference);
    std::vector<char> moved(strands.numStrands(), 0);
    if (nearestOut) nearestOut->assign(strands.numStrands(), 0);
    auto run = [&](const tbb::blocked_range<std::size_t>& r) {
        HeadObstacle::Probe probe(head);
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
            const std::size_t n = strands.size(i), b = strands.begin(i);
            if (n == 0) continue;
            const Vec3d root = toD(strands.root(i));
            const std::uint32_t near = roots.nearest(root);
            if (nearestOut) (*nearestOut)[i] = near;
            const double own = probe.distance(root), ref = probe.distance(roots.roots[near]);
            if (!(own < ref)) continue;
            Vec3d q = root;
            if (!probe.pushOut(q, std::min(0.0, ref))) continue;
            const Vec3f shift(q - root);
            for (std::size_t k = 0; k < n; ++k) strands.positions[b + k] += shift;
            moved[i] = 1;
        }
    };
    if (threaded) tbb::parallel_for(tbb::blocked_range<std::size_t>(0, strands.numStrands(), 256), run);
    else run(tbb::blocked_range<std::size_t>(0, strands.numStrands()));
    std::size_t count = 0;
    for (char m : moved) count += std::size_t(m);
    return count;
}

std::vector<float> referenceDepthAllowance(const StrandSet& strands, const StrandSet& reference, const HeadObstacle& head, bool threaded,
                                           const std::vector<std::uint32_t>* nearestIn)
{
    std::vector<float> allowed(strands.numVertices(), 0.f);
    if (head.empty() || strands.empty()) return allowed;
    if (reference.numStrands() == 0) throw ValueError("head collision: the reference hair has no strands");
    if (nearestIn && nearestIn->size() != strands.numStrands()) {
        throw ValueError("head collision: " + std::to_string(nearestIn->size()) + " nearest reference strands for " +
                         std::to_string(strands.numStrands()) + " strands");
    }
    std::unique_ptr<RootTree> roots;
    if (!nearestIn) roots = std::make_unique<RootTree>(reference);
    auto run = [&](const tbb::blocked_range<std::size_t>& r) {
        HeadObstacle::Probe probe(head);
        std::vector<double> refArc, refDepth;
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
            const std::size_t n = strands.size(i), b = strands.begin(i);
            if (n == 0) continue;
            const Vec3d root = toD(strands.root(i));
            const std::uint32_t nearest = nearestIn ? (*nearestIn)[i] : roots->nearest(root);
            if (nearest >= reference.numStrands()) continue;
            // The reference strand's depth by arc length.
            const std::size_t m = reference.size(nearest), rb = reference.begin(nearest);
            if (m == 0) continue;
            refArc.assign(m, 0.0);
            refDepth.assign(m, 0.0);
            for (std::size_t k = 0; k < m; ++k) {
                const Vec3d p = toD(reference.positions[rb + k]);
                if (k) refArc[k] = refArc[k - 1] + (p - toD(reference.positions[rb + k - 1])).length();
                refDepth[k] = std::max(0.0, -probe.distance(p));
            }
            double arc = 0.0;
            std::size_t j = 0;
            for (std::size_t k = 0; k < n; ++k) {
                if (k) arc += (toD(strands.positions[b + k]) - toD(strands.positions[b + k - 1])).length();
                while (j + 1 < m && refArc[j + 1] < arc) ++j;
                double depth = refDepth[j];
                if (j + 1 < m && refArc[j + 1] > refArc[j]) {
                    const double t = std::clamp((arc - refArc[j]) / (refArc[j + 1] - refArc[j]), 0.0, 1.0);
                    depth += t * (refDepth[j + 1] - refDepth[j]);
                }
                allowed[b + k] = float(depth);
            }
            // Where the reference leaves the head its depth drops within a segment, and a root
            // deeper than the reference's has further to rise.
            float* a = allowed.data() + b;
            a[0] = std::max(a[0], float(std::max(0.0, -probe.distance(root))));
            limitAllowanceFall(strands.positions.data() + b, n, a);
        }
    };
    if (threaded) tbb::parallel_for(tbb::blocked_range<std::size_t>(0, strands.numStrands(), 256), run);
    else run(tbb::blocked_range<std::size_t>(0, strands.numStrands()));
    return allowed;
}

void limitAllowanceFall(const Vec3f* positions, std::size_t n, float* allowed)
{
    constexpr double kRise = 0.57735027;  // tan 30°
    for (std::size_t k = 1; k < n; ++k) {
        const double seg = (toD(positions[k]) - toD(positions[k - 1])).length();
        allowed[k] = std::max(allowed[k], float(allowed[k - 1] - kRise * seg));
    }
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
