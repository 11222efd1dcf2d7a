#include "../TestUtil.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/Random.h>
#include <vdbhair/helicoid/AnalyticHelicoidSampler.h>
#include <vdbhair/helicoid/Helicoid.h>
#include <vdbhair/helicoid/Scene.h>
#include <vdbhair/helicoid/Waviness.h>
#include <vdbhair/helicoid/Wisp.h>

#include <cmath>
#include <random>

using namespace vdbhair;

namespace {
HelicoidTrace trace(const HelicoidParams& k, double length, double step, HelicoidIntegrator integ = HelicoidIntegrator::Euler,
                    const FrameD& frame = FrameD::fromTangentNormal(Vec3d(1, 0, 0), Vec3d(0, 1, 0)), const Vec3d& root = Vec3d(0.0))
{
    HelicoidTrace t;
    tracePHelicoid(root, frame, {HelicoidPiece{k, length, 0.0}}, step, integ, t);
    return t;
}
} // namespace

TEST_CASE("tracePHelicoid: k = 0 traces a straight line of length L", "[helicoid]")
{
    const FrameD f = FrameD::fromTangentNormal(Vec3d(1, 2, 2), Vec3d(0, 0, 1));
    const HelicoidTrace t = trace({}, 3.05, 0.1, HelicoidIntegrator::Euler, f, Vec3d(1, 1, 1));
    REQUIRE(t.points.size() == 32);  // 30 steps of 0.1 and a last one of 0.05
    REQUIRE(t.arc.back() == Approx(3.05));
    REQUIRE((t.points.back() - (Vec3d(1, 1, 1) + 3.05 * f.t)).length() < 1e-12);
    for (const FrameD& fr : t.frames) REQUIRE((fr.t - f.t).length() < 1e-12);
}

TEST_CASE("tracePHelicoid: k = (kT,0,0,0) traces the circle of radius 1/kT about p0 + E_N/kT, through full turns", "[helicoid]")
{
    const double kT = 2.0, r = 1.0 / kT, turns = 3.0, L = turns * 2.0 * M_PI * r;
    const FrameD f = FrameD::fromTangentNormal(Vec3d(0, 0, 1), Vec3d(1, 0, 0));
    const Vec3d root(0.5, -1.0, 2.0), centre = root + f.n * r;
    double errEuler[2];
    for (int level = 0; level < 2; ++level) {
        const double step = level == 0 ? 0.01 : 0.005;
        const HelicoidTrace t = trace({kT, 0, 0, 0}, L, step, HelicoidIntegrator::Euler, f, root);
        double worst = 0.0;
        for (const Vec3d& p : t.points) {
            REQUIRE(std::abs((p - root).dot(f.b)) < 1e-12);  // stays in the E_T–E_N plane
            worst = std::max(worst, std::abs((p - centre).length() - r));
        }
        errEuler[level] = worst;
    }
    // Euler spirals out by theta·h/2 (theta = 6π here); halving the step halves it.
    CAPTURE(errEuler[0], errEuler[1]);
    REQUIRE(errEuler[0] < 1.05 * 6.0 * M_PI * 0.01 / 2.0);
    REQUIRE(errEuler[0] / errEuler[1] == Approx(2.0).epsilon(0.05));
    // RK4 stays on the circle, and after three turns it is back at the root.
    const HelicoidTrace rk = trace({kT, 0, 0, 0}, L, 0.01, HelicoidIntegrator::RK4, f, root);
    for (const Vec3d& p : rk.points) REQUIRE(std::abs((p - centre).length() - r) < 1e-9);
    REQUIRE((rk.points.back() - root).length() < 1e-8);
}

TEST_CASE("tracePHelicoid: k = (0,kN,0,0) gives straight streamlines fanning out from p0 - E_T/kN", "[helicoid]")
// (in each plane parallel to E_T–E_N: the fan's centre is the line through p0 - E_T/kN along E_B)
{
    const double kN = 0.5;
    const FrameD f = FrameD::fromTangentNormal(Vec3d(1, 0, 0), Vec3d(0, 1, 0));
    Helicoid h;
    h.k = {0, kN, 0, 0};
    h.q = f;
    for (const Vec3d& start : {Vec3d(0, 0.3, 0.0), Vec3d(0.2, -0.4, 0.0), Vec3d(-0.1, 0.0, 0.5), Vec3d(0.0, 0.3, 0.1)}) {
        const Vec3d sink = h.p0 - f.t / kN + f.b * start.dot(f.b);
        HelicoidTrace t;
        const std::vector<Helicoid> field{h};
        tracePHelicoid(start, f, {HelicoidPiece{h.k, 2.0, 0.0}}, 0.01, HelicoidIntegrator::Euler, t, &field);
        const Vec3d dir = (start - sink).unit();
        for (const Vec3d& p : t.points) {
            CAPTURE(start, p);
            const Vec3d d = p - sink;
            REQUIRE((d - dir * d.dot(dir)).length() < 1e-9);  // on the ray from the sink through the start
        }
    }
}

TEST_CASE("Helicoid::axisDistance: zero on the singular axis, 1/|k| at the root, and theta turns about it like a vortex", "[helicoid]")
{
    Helicoid h;
    h.k = {0.7, -0.4, 0.3, 0.2};
    h.q = FrameD::fromTangentNormal(Vec3d(0.3, -1, 0.2), Vec3d(1, 0, 0.5));
    h.p0 = Vec3d(1, 2, 3);
    const double K2 = 0.7 * 0.7 + 0.4 * 0.4;
    REQUIRE(h.axisDistance(h.p0) == Approx(1.0 / std::sqrt(K2)).epsilon(1e-12));
    // The axis: both arguments of Eq. 1's atan2 vanish at y = (-kN, kT, s) / (kT² + kN²), for any s.
    const Vec3d axis = h.p0 + (h.q.t * 0.4 + h.q.n * 0.7) / K2;
    for (double s : {-1.0, 0.0, 2.5}) REQUIRE(h.axisDistance(axis + s * h.q.b) < 1e-12);
    // At distance r in the plane normal to the axis, theta is the polar angle psi about it plus
    // arg(kN + i kT) (v + i u = r (kN + i kT) e^{i psi}): its gradient is 1/r.
    for (double r : {1e-3, 0.1, 2.0}) {
        double ref = 0.0;
        const double t0 = h.theta(axis + r * h.q.t, ref);
        for (double psi : {0.5, 1.5, 3.0}) {
            const Vec3d p = axis + r * (std::cos(psi) * h.q.t + std::sin(psi) * h.q.n);
            CAPTURE(r, psi);
            REQUIRE(h.axisDistance(p) == Approx(r).epsilon(1e-9));
            REQUIRE(std::remainder(h.theta(p, ref) - t0 - psi, 2.0 * M_PI) == Approx(0.0).margin(1e-6));
        }
    }
    h.k = {0.0, 0.0, 0.5, 0.1};  // no axis
    REQUIRE(std::isinf(h.axisDistance(h.p0)));
}

TEST_CASE("tracePHelicoid: RK4 at h and h/16 agree where the trace keeps kAxisClearanceSteps from the axis, not across it", "[helicoid]")
{
    // Seeded pieces with kN < 0 (the flow spirals onto the axis), traced at h and h/16: a trace
    // that keeps its distance is a streamline, one that steps near the axis is an artefact of h.
    std::mt19937 rng(1);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    const double h = 0.05;
    int clear = 0, crossing = 0;
    for (int trial = 0; trial < 40; ++trial) {
        const HelicoidParams k{2.0 * std::abs(u(rng)), -2.0 * std::abs(u(rng)), u(rng), u(rng)};
        for (double L : {0.5, 1.0, 2.0, 4.0}) {
            const HelicoidTrace a = trace(k, L, h, HelicoidIntegrator::RK4), b = trace(k, L, h / 16, HelicoidIntegrator::RK4);
            const double clearance = traceClearance(a, h), moved = (a.points.back() - b.points.back()).length();
            CAPTURE(trial, k.kT, k.kN, k.kB, k.alpha, L, clearance, moved);
            if (clearance >= kAxisClearanceSteps) {
                ++clear;
                REQUIRE(moved < 1e-4 * L);
            } else if (clearance >= GrowOptions{}.nearAxisSteps) {
                REQUIRE(moved < 1e-3 * L);  // grow does not warn about these
            } else if (clearance < 0.1) {
                ++crossing;
            }
        }
    }
    REQUIRE(clear >= 40);
    REQUIRE(crossing >= 20);
    // One crossing, by name: within 0.04 steps of the axis, the end moves by 60 % of the length.
    const HelicoidParams k{1.742, -1.385, -0.373, 0.049};
    const HelicoidTrace a = trace(k, 4.0, h, HelicoidIntegrator::RK4), b = trace(k, 4.0, h / 16, HelicoidIntegrator::RK4);
    REQUIRE(traceClearance(a, h) < 0.1);
    REQUIRE((a.points.back() - b.points.back()).length() > 0.5 * 4.0);
}

TEST_CASE("tracePHelicoid: theta unwraps through full turns, so phi = alpha·theta stays continuous", "[helicoid]")
{
    // Large alpha makes any 2π jump of theta a visible jump of the frame.
    const HelicoidTrace t = trace({2.0, 0.0, 0.0, 0.25}, 4.0 * 2.0 * M_PI * 0.5, 0.005, HelicoidIntegrator::RK4);
    for (std::size_t i = 1; i < t.frames.size(); ++i) {
        CAPTURE(i);
        REQUIRE(t.frames[i].t.dot(t.frames[i - 1].t) > std::cos(0.05));
        REQUIRE(t.frames[i].b.dot(t.frames[i - 1].b) > std::cos(0.05));
    }
    // phi grew past 2π·alpha: the strand has left the plane far more than one turn would allow.
    REQUIRE(std::abs(t.frames.back().t.z()) > 0.5);
}

TEST_CASE("tracePHelicoid: p-helicoid joints keep the frame (C1, and more)", "[helicoid]")
{
    const std::vector<HelicoidPiece> pieces{{{1.0, -0.1, 0.3, 1.0}, 1.5, 0.0}, {{-2.0, 0.4, 1.0, 0.2}, 1.0, 0.0}, {{0.5, 0.5, -0.5, 0.0}, 0.7, 0.0}};
    HelicoidTrace t;
    tracePHelicoid(Vec3d(0.0), FrameD::fromTangentNormal(Vec3d(0, 1, 0), Vec3d(1, 0, 0)), pieces, 0.001, HelicoidIntegrator::Euler, t);
    REQUIRE(t.joints.size() == 3);
    REQUIRE(t.arc.back() == Approx(3.2));
    for (std::size_t j = 1; j < t.joints.size(); ++j) {
        const std::size_t i = t.joints[j];
        // The new piece starts at the joint with the frame of Eq. 2 there.
        REQUIRE((t.pieces[j].p0 - t.points[i]).length() < 1e-12);
        const Vec3d before = (t.points[i] - t.points[i - 1]).unit(), after = (t.points[i + 1] - t.points[i]).unit();
        CAPTURE(j, before, after);
        REQUIRE(before.dot(after) > std::cos(0.01));  // one step's turn at most
        REQUIRE((t.pieces[j].q.t - after).length() < 1e-9);
    }
    // A roll turns the next piece's frame about the tangent, keeping the tangent.
    std::vector<HelicoidPiece> rolled = pieces;
    rolled[1].roll = 0.7;
    HelicoidTrace tr;
    tracePHelicoid(Vec3d(0.0), FrameD::fromTangentNormal(Vec3d(0, 1, 0), Vec3d(1, 0, 0)), rolled, 0.001, HelicoidIntegrator::Euler, tr);
    REQUIRE((tr.pieces[1].q.t - t.pieces[1].q.t).length() < 1e-12);
    REQUIRE(tr.pieces[1].q.n.dot(t.pieces[1].q.n) == Approx(std::cos(0.7)));
}

TEST_CASE("traceWisp: wisp strands follow the guide's field at their own points", "[helicoid]")
{
    const std::vector<HelicoidPiece> pieces{{{1.0, -0.1, 0.3, 1.0}, 1.0, 0.0}, {{0.5, 0.2, -0.4, 0.5}, 1.0, 0.3}};
    HelicoidTrace guide, wisp;
    tracePHelicoid(Vec3d(0.0), FrameD::fromTangentNormal(Vec3d(1, 0, 0), Vec3d(0, 1, 0)), pieces, 0.01, HelicoidIntegrator::Euler, guide);
    for (int w = 0; w < 20; ++w) {
        Rng rng(7, 0, std::uint64_t(w + 1));
        traceWisp(guide, pieces, WispParams{20, 0.05, 0.0}, 0.01, HelicoidIntegrator::Euler, rng, wisp);
        REQUIRE(wisp.points.size() == guide.points.size());
        const Vec3d off = wisp.points[0] - guide.points[0];
        REQUIRE(off.length() <= 0.05 + 1e-12);
        REQUIRE(std::abs(off.dot(guide.frames[0].t)) < 1e-12);  // in the E_N–E_B plane
        REQUIRE(off.length() > 0.0);  // not a copy of the guide
        for (std::size_t i = 0; i + 1 < wisp.points.size(); ++i) {
            const std::size_t piece = i >= guide.joints[1] ? 1 : 0;
            double th = guide.pieces[piece].theta(wisp.points[i], 0.0);
            const Vec3d expected = guide.pieces[piece].tangent(wisp.points[i], th);
            const Vec3d d = (wisp.points[i + 1] - wisp.points[i]).unit();
            CAPTURE(w, i);
            REQUIRE(d.dot(expected) > 1.0 - 1e-9);
        }
    }
}

TEST_CASE("applyWaviness: the offset is exactly the amplitude, in the normal plane", "[helicoid]")
{
    const HelicoidTrace t = trace({1.0, -0.1, 0.3, 1.0}, 2.0, 0.01);
    std::vector<Vec3f> wavy(t.points.size());
    Rng rng(1);
    applyWaviness(t, WavinessParams{0.02, 40.0, 0.0, 0.0}, rng, wavy.data());
    for (std::size_t i = 0; i < t.points.size(); ++i) {
        const Vec3d d = Vec3d(wavy[i]) - t.points[i];
        REQUIRE(d.length() == Approx(0.02).epsilon(1e-4));
        REQUIRE(std::abs(d.dot(t.frames[i].t)) < 1e-6);
    }
    // Eq. 4 at s = 0: a·E_B.
    REQUIRE((Vec3d(wavy[0]) - (t.points[0] + 0.02 * t.frames[0].b)).length() < 1e-6);
}

TEST_CASE("traceStreamline: the analytic helicoid sampler traces tracePHelicoid's RK4 streamline, theta unwrapped through turns", "[helicoid]")
{
    int fullTurns = 0;
    for (std::uint64_t seed = 0; seed < 12; ++seed) {
        Rng rng(99, seed);
        Helicoid h;
        // Curvatures of up to 3 / world unit, alpha up to 0.5: several full turns over L.
        h.k = {3.0 * (rng.uniform() - 0.5) * 2.0, 0.5 * rng.uniform(), 2.0 * (rng.uniform() - 0.5), rng.uniform() - 0.5};
        h.q = FrameD::fromTangentNormal(Vec3d(rng.uniform() - 0.5, rng.uniform() - 0.5, 1.0), Vec3d(1.0, rng.uniform(), 0.0));
        h.p0 = Vec3d(rng.uniform(), rng.uniform(), rng.uniform());
        const double L = 4.0 + 8.0 * rng.uniform(), step = 0.01;
        CAPTURE(seed, h.k.kT, h.k.kN, h.k.kB, h.k.alpha, L);
        HelicoidPiece piece;
        piece.k = h.k;
        piece.length = L;
        HelicoidTrace expected;
        tracePHelicoid(h.p0, h.q, {piece}, step, HelicoidIntegrator::RK4, expected);

        AnalyticHelicoidSampler sampler(h);
        StreamlineRules rules;
        rules.integrator = Integrator::RK4;
        rules.step = step;
        std::vector<Vec3d> points;
        REQUIRE(traceStreamline(sampler, h.p0, L, rules, points) == StopReason::FullLength);
        REQUIRE(points.size() == expected.points.size());
        double worst = 0.0;
        for (std::size_t i = 0; i < points.size(); ++i) worst = std::max(worst, (points[i] - expected.points[i]).length());
        CAPTURE(worst);
        REQUIRE(worst < 1e-12 * L);
        // Through full turns (theta unwrapped past 2π), where a sampler that did not track theta
        // would turn phi = alpha·theta back by 2π·alpha.
        double th = 0.0;
        for (const Vec3d& p : expected.points) th = h.theta(p, th);
        if (std::abs(th) > 2.0 * M_PI && h.k.alpha != 0.0) ++fullTurns;
    }
    REQUIRE(fullTurns >= 2);  // seeds 0-11 turn past 2π twice with alpha != 0
}

TEST_CASE("StreamlineIntegrator: Euler, RK2, RK3 and RK4 converge on a circle at orders 1, 2, 3 and 4", "[helicoid]")
{
    // The circle of radius r = 1/kT traced for one turn: the end point's distance from the root
    // is the global error, which falls as h^order (halving the step divides it by 2^order; from
    // 256 steps a turn on, RK2 and RK4 are in their asymptotic range).
    // Both samplers (branchy and branchless Eq. 1) give the same orders and agree to 1e-12.
    const double kT = 2.0, r = 1.0 / kT, L = 2.0 * M_PI * r;
    Helicoid h;
    h.k = {kT, 0.0, 0.0, 0.0};
    h.q = FrameD::fromTangentNormal(Vec3d(0, 0, 1), Vec3d(1, 0, 0));
    h.p0 = Vec3d(0.5, -1.0, 2.0);
    auto endError = [&](Integrator integ, double step, bool branchless) {
        StreamlineRules rules;
        rules.integrator = integ;
        rules.step = step;
        std::vector<Vec3d> points;
        if (branchless) {
            BranchlessHelicoidSampler sampler(h);
            REQUIRE(traceStreamline(sampler, h.p0, L, rules, points) == StopReason::FullLength);
        } else {
            AnalyticHelicoidSampler sampler(h);
            REQUIRE(traceStreamline(sampler, h.p0, L, rules, points) == StopReason::FullLength);
        }
        return (points.back() - h.p0).length();
    };
    const std::pair<Integrator, double> orders[] = {
        {Integrator::Euler, 1.0}, {Integrator::RK2, 2.0}, {Integrator::RK3, 3.0}, {Integrator::RK4, 4.0}};
    for (const auto& [integ, order] : orders) {
        const double coarse = endError(integ, L / 256.0, false), fine = endError(integ, L / 512.0, false);
        CAPTURE(integratorName(integ), coarse, fine);
        REQUIRE(coarse > 1e-12);  // a real error, not rounding
        REQUIRE(std::log2(coarse / fine) == Approx(order).margin(0.25));
        REQUIRE(std::abs(endError(integ, L / 512.0, true) - fine) < 1e-12);
    }
    REQUIRE(integratorFromName("rk3") == Integrator::RK3);
    REQUIRE(std::string(integratorName(Integrator::RK3)) == "rk3");
}

TEST_CASE("tracePHelicoids: the wisps' SIMD Euler lanes hold to the engine's Euler through each root's own trace", "[helicoid]")
{
    const std::vector<HelicoidPiece> pieces{{{2.0, -0.3, 0.7, 0.8}, 3.0, 0.0}};
    HelicoidTrace guide;
    tracePHelicoid(Vec3d(0.2, -0.1, 0.4), FrameD::fromTangentNormal(Vec3d(1, 0.2, 0), Vec3d(0, 1, 0.3)), pieces, 0.01,
                   HelicoidIntegrator::Euler, guide);
    Rng rng(5);
    std::vector<Vec3d> roots(11);  // more than one group of eight lanes, the last one partly idle
    for (Vec3d& r : roots) r = guide.points[0] + Vec3d(rng.uniform() - 0.5, rng.uniform() - 0.5, rng.uniform() - 0.5) * 0.1;
    std::vector<HelicoidTrace> lanes(roots.size());
    tracePHelicoids(roots.data(), roots.size(), guide.pieces[0].q, pieces, 0.01, HelicoidIntegrator::Euler, lanes.data(), &guide.pieces);
    for (std::size_t i = 0; i < roots.size(); ++i) {
        AnalyticHelicoidSampler sampler(guide.pieces[0]);
        StreamlineRules rules;
        rules.step = 0.01;
        std::vector<Vec3d> points;
        REQUIRE(traceStreamline(sampler, roots[i], pieces[0].length, rules, points) == StopReason::FullLength);
        REQUIRE(points.size() == lanes[i].points.size());
        double worst = 0.0;
        for (std::size_t k = 0; k < points.size(); ++k) worst = std::max(worst, (points[k] - lanes[i].points[k]).length());
        CAPTURE(i, worst);
        REQUIRE(worst < 1e-9 * pieces[0].length);  // the lanes' own atan2 and sin/cos (FastMath.h)
    }
}

TEST_CASE("tracePHelicoidPoints: every lane on its own p-helicoid holds to tracePHelicoid (Euler and RK4), and growScene uses it", "[helicoid]")
{
    // 21 strands (two full groups of eight lanes and one partly idle), each with its own root,
    // frame, 1 to 5 pieces of lengths that are not multiples of the step (one of zero length),
    // rolls, and its own step; the lanes finish at different times and take new strands.
    Rng rng(11);
    const auto u = [&](double a, double b) { return a + (b - a) * rng.uniform(); };
    std::vector<std::vector<HelicoidPiece>> pieces(21);
    std::vector<PHelicoidRequest> req(21);
    for (std::size_t i = 0; i < req.size(); ++i) {
        const int n = 1 + int(i % 5);
        for (int p = 0; p < n; ++p) {
            const double length = (i == 7 && p == 1) ? 0.0 : u(0.2, 1.3);
            pieces[i].push_back({{u(-3.0, 3.0), u(-0.5, 0.5), u(-1.0, 1.0), u(-0.6, 0.6)}, length, u(-1.0, 1.0)});
        }
        req[i].root = Vec3d(u(-1, 1), u(-1, 1), u(-1, 1));
        req[i].frame = FrameD::fromTangentNormal(Vec3d(u(-1, 1), u(-1, 1), 1.0), Vec3d(1.0, u(-0.3, 0.3), 0.0));
        req[i].pieces = &pieces[i];
        req[i].step = i % 3 == 0 ? 0.013 : 0.02;
    }
    for (const HelicoidIntegrator integrator : {HelicoidIntegrator::Euler, HelicoidIntegrator::RK4}) {
        std::vector<std::vector<Vec3f>> outs(req.size());
        std::vector<Vec3f*> dst(req.size());
        for (std::size_t i = 0; i < req.size(); ++i) {
            std::size_t total = 1;
            for (const HelicoidPiece& pc : pieces[i]) total += stepCount(pc.length, req[i].step);
            outs[i].assign(total, Vec3f(std::numeric_limits<float>::quiet_NaN()));
            dst[i] = outs[i].data();
        }
        tracePHelicoidPoints(req.data(), req.size(), integrator, dst.data());

        Scene scene;
        scene.step = 0.02;
        scene.integrator = integrator;
        for (std::size_t i = 0; i < req.size(); ++i) {
            HelicoidTrace t;
            tracePHelicoid(req[i].root, req[i].frame, pieces[i], req[i].step, integrator, t);
            REQUIRE(t.points.size() == outs[i].size());
            double worst = 0.0;
            for (std::size_t k = 0; k < t.points.size(); ++k) worst = std::max(worst, (Vec3d(outs[i][k]) - t.points[k]).length());
            CAPTURE(i, worst);
            REQUIRE(worst < 1e-5);  // float output of the same steps (the lanes' branchless atan2 and sin/cos)
            SceneGuide g;
            g.root = req[i].root;
            g.frame = req[i].frame;
            g.pieces = pieces[i];
            g.step = req[i].step;
            scene.guides.push_back(g);
        }
        // A scene of such hairs grows through the lanes: the same points, with any thread count.
        for (bool threaded : {false, true}) {
            const StrandSet grown = growScene(scene, {}, threaded);
            REQUIRE(grown.numStrands() == req.size());
            for (std::size_t i = 0; i < req.size(); ++i) {
                REQUIRE(grown.size(i) == outs[i].size());
                for (std::size_t k = 0; k < outs[i].size(); ++k) REQUIRE(grown.data(i)[k] == outs[i][k]);
            }
        }
    }
}
