#include "../TestUtil.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/field/HeadCollision.h>
#include <vdbhair/helicoid/GuideInterpolation.h>
#include <vdbhair/helicoid/FrameAverage.h>
#include <vdbhair/helicoid/HelicoidInterpolation.h>
#include <vdbhair/helicoid/PointInterpolation.h>
#include <vdbhair/helicoid/Scene.h>
#include <vdbhair/helicoid/ShepardWeights.h>
#include <vdbhair/strands/Resample.h>

#include <tbb/global_control.h>

#include <cmath>
#include <random>

using namespace vdbhair;
using Catch::Matchers::Contains;

namespace {

SceneGuide makeGuide(const Vec3d& root, const FrameD& frame, const std::vector<HelicoidPiece>& pieces)
{
    SceneGuide g;
    g.root = root;
    g.frame = frame;
    g.pieces = pieces;
    return g;
}

HelicoidPiece piece(double kT, double kN, double kB, double alpha, double length, double roll = 0.0)
{
    HelicoidPiece p;
    p.k = {kT, kN, kB, alpha};
    p.length = length;
    p.roll = roll;
    return p;
}

/// Discrete curvature at the interior vertices of strand @a i resampled to @a m points by arc length.
std::vector<double> curvatureProfile(const StrandSet& s, std::size_t i, std::size_t m = 61)
{
    std::vector<Vec3f> r(m);
    resamplePolyline(s.positions.data() + s.begin(i), s.size(i), m, r.data());
    std::vector<double> k;
    for (std::size_t j = 1; j + 1 < m; ++j) {
        const Vec3d a(r[j] - r[j - 1]), b(r[j + 1] - r[j]);
        const double c = std::clamp(a.dot(b) / (a.length() * b.length()), -1.0, 1.0);
        k.push_back(std::acos(c) / (0.5 * (a.length() + b.length())));
    }
    return k;
}

double meanAbsDiff(const std::vector<double>& a, const std::vector<double>& b)
{
    double s = 0.0;
    for (std::size_t i = 0; i < a.size(); ++i) s += std::abs(a[i] - b[i]);
    return s / double(a.size());
}

double mean(const std::vector<double>& a)
{
    double s = 0.0;
    for (double v : a) s += v;
    return s / double(a.size());
}

/// Roots on the segment from @a a to @a b, @a n of them, ends included.
InterpolationRoots rootsOnLine(const Vec3d& a, const Vec3d& b, int n)
{
    InterpolationRoots r;
    for (int i = 0; i < n; ++i) r.positions.push_back(a + (b - a) * (double(i) / double(n - 1)));
    return r;
}

const FrameD kUp = FrameD::fromTangentNormal(Vec3d(0, 0, 1), Vec3d(1, 0, 0));

/// Two p-helicoid guides a unit apart with alpha, kN, kB and rolls (curves in space, of 2.5
/// units), traced with RK4 at @a step.
Scene twoSpatialGuides(double step)
{
    Scene scene;
    scene.step = step;
    scene.integrator = HelicoidIntegrator::RK4;
    scene.guides.push_back(makeGuide(Vec3d(0, 0, 0), kUp.rolled(0.7),
                                     {piece(1.0, 0.2, 0.3, 0.5, 1.0, 0.2), piece(2.0, 0.1, -0.4, 0.2, 0.6, 1.3), piece(0.5, -0.3, 0.0, 0.1, 0.9, -2.0)}));
    scene.guides.push_back(makeGuide(Vec3d(1, 0, 0), kUp.rolled(-0.4), {piece(0.3, 0.0, 0.2, 0.0, 1.5), piece(1.0, 0.5, 0.0, 0.0, 1.0, 0.5)}));
    return scene;
}

} // namespace

TEST_CASE("GuideLocator: Shepard and faded weights sum to 1; a coincident root takes its guide alone", "[helicoid][interp]")
{
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    std::vector<Vec3d> roots;
    for (int i = 0; i < 40; ++i) roots.emplace_back(u(rng), u(rng), u(rng));
    const GuideLocator loc(roots);
    std::vector<GuideWeight> w;
    for (int t = 0; t < 200; ++t) {
        const Vec3d x(u(rng), u(rng), u(rng));
        for (int k : {-1, 1, 3, 8, 100}) {
            ShepardParams sp;
            sp.neighbors = k;
            sp.power = 1.0 + double(t % 4);
            loc.shepardWeights(x, sp, w);
            double sum = 0.0;
            for (const GuideWeight& g : w) { sum += g.weight; REQUIRE(g.weight > 0.0); }
            CAPTURE(t, k);
            REQUIRE(sum == Approx(1.0).margin(1e-12));
            REQUIRE(w.size() == (k < 0 || k > 40 ? 40u : std::size_t(k)));
        }
        loc.fadedWeights(x, 4, w);
        double sum = 0.0;
        for (const GuideWeight& g : w) sum += g.weight;
        REQUIRE(sum == Approx(1.0).margin(1e-12));
        REQUIRE(w.size() <= 4u);  // the fifth nearest is faded to zero
    }
    // Shepard by hand for two guides: w = d^-p / sum, p = 3.
    const GuideLocator two({Vec3d(0, 0, 0), Vec3d(3, 0, 0)});
    two.shepardWeights(Vec3d(1, 0, 0), ShepardParams{}, w);
    REQUIRE(w.size() == 2u);
    const double w0 = 1.0 / (1.0 + 1.0 / 8.0);
    for (const GuideWeight& g : w) REQUIRE(g.weight == Approx(g.guide == 0 ? w0 : 1.0 - w0).epsilon(1e-12));
    loc.shepardWeights(roots[17], ShepardParams{}, w);
    REQUIRE(w.size() == 1u);
    REQUIRE(w[0].guide == 17u);
    REQUIRE(w[0].weight == 1.0);
}

TEST_CASE("averageFrames: sign-aligned quaternions; equal frames and halfway rotations", "[helicoid][interp]")
{
    const FrameD a = kUp;
    const FrameD b = a.rolled(M_PI / 2.0);
    std::vector<FrameD> frames{a, b};
    const FrameD mid = averageFrames(frames, {{0, 0.5}, {1, 0.5}});
    const FrameD expect = a.rolled(M_PI / 4.0);
    REQUIRE((mid.t - expect.t).length() < 1e-12);
    REQUIRE((mid.n - expect.n).length() < 1e-12);
    // q and -q: a frame given by a quaternion of the other sign still averages to itself.
    const std::array<double, 4> q = frameToQuaternion(b);
    const FrameD back = quaternionToFrame({-q[0], -q[1], -q[2], -q[3]});
    std::vector<FrameD> same{b, back};
    const FrameD avg = averageFrames(same, {{0, 0.3}, {1, 0.7}});
    REQUIRE((avg.t - b.t).length() < 1e-12);
    REQUIRE((avg.n - b.n).length() < 1e-12);
}

TEST_CASE("interpolateHelicoids: Fig. 6, two pi-rotated guides vary smoothly, less than point blending", "[helicoid][interp]")
{
    Scene scene;
    scene.step = 0.01;
    const std::vector<HelicoidPiece> k{piece(1.0, -0.1, 0.3, 1.0, 3.0)};
    scene.guides.push_back(makeGuide(Vec3d(0, 0, 0), kUp, k));
    // The second guide is the first turned by π about the hair's initial direction.
    scene.guides.push_back(makeGuide(Vec3d(1, 0, 0), FrameD::fromTangentNormal(Vec3d(0, 0, 1), Vec3d(-1, 0, 0)), k));
    const InterpolationRoots roots = rootsOnLine(Vec3d(0, 0, 0), Vec3d(1, 0, 0), 11);
    const StrandSet helicoid = growScene(interpolateHelicoids(scene, roots, {}));
    const StrandSet guides = growScene(scene);
    PointInterpolationParams blender;  // Blender's node: every guide by distance alone
    blender.grouping = GuideGrouping::None;
    const StrandSet points = interpolatePoints(guides, roots, blender);
    double varHelicoid = 0.0, varPoints = 0.0;
    for (std::size_t i = 0; i + 1 < roots.positions.size(); ++i) {
        varHelicoid += meanAbsDiff(curvatureProfile(helicoid, i), curvatureProfile(helicoid, i + 1));
        varPoints += meanAbsDiff(curvatureProfile(points, i), curvatureProfile(points, i + 1));
    }
    CAPTURE(varHelicoid, varPoints);
    // Same k everywhere: every interpolant has the guides' curvature; blended points straighten between them.
    REQUIRE(varHelicoid < 0.2 * varPoints);
    const double kGuide = mean(curvatureProfile(guides, 0));
    REQUIRE(mean(curvatureProfile(helicoid, 5)) == Approx(kGuide).epsilon(0.02));
    REQUIRE(mean(curvatureProfile(points, 5)) < 0.5 * kGuide);
}

TEST_CASE("interpolateHelicoids: the kT sign rule removes the straight helicoid between equal guides", "[helicoid][interp]")
{
    Scene scene;
    scene.step = 0.01;
    scene.guides.push_back(makeGuide(Vec3d(0, 0, 0), kUp, {piece(1.0, -0.1, 0.3, 1.0, 3.0)}));
    // The same curve described with -kT and a frame turned by π about E_T.
    scene.guides.push_back(makeGuide(Vec3d(1, 0, 0), kUp.rolled(M_PI), {piece(-1.0, -0.1, 0.3, 1.0, 3.0)}));
    const StrandSet guides = growScene(scene);
    float worst = 0.f;
    for (std::size_t v = 0; v < guides.size(0); ++v) {
        worst = std::max(worst, (guides.positions[guides.begin(1) + v] - Vec3f(1, 0, 0) - guides.positions[v]).length());
    }
    REQUIRE(worst < 1e-5f);  // the symmetry the rule relies on (a half turn about E_T)
    const InterpolationRoots mid = rootsOnLine(Vec3d(0.5, 0, 0), Vec3d(0.5, 0, 0), 2);
    HelicoidInterpolationParams with, without;
    without.kTSignRule = false;
    const StrandSet a = growScene(interpolateHelicoids(scene, mid, with));
    const StrandSet b = growScene(interpolateHelicoids(scene, mid, without));
    const std::vector<double> kGuide = curvatureProfile(guides, 0);
    CAPTURE(mean(kGuide), mean(curvatureProfile(a, 0)), mean(curvatureProfile(b, 0)));
    REQUIRE(meanAbsDiff(curvatureProfile(a, 0), kGuide) < 0.01 * mean(kGuide));
    REQUIRE(mean(curvatureProfile(b, 0)) < 0.5 * mean(kGuide));
}

TEST_CASE("interpolateHelicoids: at a guide's root the guide itself, bit for bit", "[helicoid][interp]")
{
    Scene scene;
    scene.step = 0.02;
    scene.guides.push_back(makeGuide(Vec3d(0, 0, 0), kUp, {piece(1.0, 0.2, 0.3, 0.5, 1.0), piece(-2.0, 0.0, 0.1, 0.0, 1.5, 0.3)}));
    scene.guides.push_back(makeGuide(Vec3d(1, 0, 0), kUp.rolled(0.4), {piece(0.5, 0.0, 0.0, 0.0, 2.0)}));
    scene.guides.back().waviness = WavinessParams{0.01, 30.0, 0.2, 0.0};
    scene.guides.push_back(makeGuide(Vec3d(0, 1, 0), kUp, {piece(2.0, 0.1, 0.0, 0.0, 0.7), piece(1.0, 0.0, 0.0, 0.0, 0.7), piece(0.0, 0.5, 0.0, 0.0, 0.7)}));
    InterpolationRoots roots;
    for (const SceneGuide& g : scene.guides) roots.positions.push_back(g.root);
    const StrandSet grown = growScene(interpolateHelicoids(scene, roots, {}));
    const StrandSet guides = growScene(scene);
    REQUIRE(grown.offsets == guides.offsets);
    REQUIRE(grown.positions == guides.positions);
}

TEST_CASE("interpolateHelicoids: a single guide reproduces itself at every root, moved and turned with the root frame", "[helicoid][interp]")
{
    Scene scene;
    scene.step = 0.01;
    scene.guides.push_back(makeGuide(Vec3d(0, 0, 1), kUp, {piece(1.5, 0.2, 0.4, 0.3, 1.0), piece(0.5, 0.0, 0.0, 0.0, 1.0, 0.5)}));
    const StrandSet guide = growScene(scene);
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    InterpolationRoots world, surface;
    for (int i = 0; i < 20; ++i) {
        Vec3d n(u(rng), u(rng), u(rng));
        n.normalize();
        world.positions.push_back(Vec3d(u(rng), u(rng), u(rng)) * 5.0);
        surface.positions.push_back(n);  // roots on the unit sphere, radial normals
        surface.normals.push_back(n);
    }
    const StrandSet w = growScene(interpolateHelicoids(scene, world, {}));
    for (std::size_t i = 0; i < world.positions.size(); ++i) {
        REQUIRE(w.size(i) == guide.size(0));
        const Vec3f shift = Vec3f(world.positions[i]) - guide.positions[0];
        float worst = 0.f;
        for (std::size_t v = 0; v < guide.size(0); ++v) worst = std::max(worst, (w.positions[w.begin(i) + v] - guide.positions[v] - shift).length());
        CAPTURE(i);
        REQUIRE(worst < 1e-5f);
    }
    const std::vector<Vec3d> guideNormal{Vec3d(0, 0, 1)};
    const StrandSet s = growScene(interpolateHelicoids(scene, surface, {}, guideNormal));
    const FrameD Wg = surfaceFrame(Vec3d(0, 0, 1), Vec3d(0, 1, 0));
    for (std::size_t i = 0; i < surface.positions.size(); ++i) {
        const FrameD Wr = surfaceFrame(surface.normals[i], Vec3d(0, 1, 0));
        float worst = 0.f;
        for (std::size_t v = 0; v < guide.size(0); ++v) {
            const Vec3d d(guide.positions[v] - guide.positions[0]);
            const Vec3d local(d.dot(Wg.t), d.dot(Wg.n), d.dot(Wg.b));
            const Vec3d expect = surface.positions[i] + local.x() * Wr.t + local.y() * Wr.n + local.z() * Wr.b;
            worst = std::max(worst, float((Vec3d(s.positions[s.begin(i) + v]) - expect).length()));
        }
        CAPTURE(i);
        REQUIRE(worst < 1e-5f);
    }
}

TEST_CASE("interpolateHelicoids: guides of 2 and 4 pieces blend with C1 joints and no jump between neighbours", "[helicoid][interp]")
{
    Scene scene;
    scene.step = 0.01;
    scene.guides.push_back(makeGuide(Vec3d(0, 0, 0), kUp, {piece(1.0, 0.1, 0.2, 0.3, 1.0), piece(2.0, -0.3, 0.0, 0.0, 1.0, 0.4)}));
    scene.guides.push_back(makeGuide(Vec3d(1, 0, 0), kUp.rolled(0.3),
                                     {piece(0.5, 0.0, 0.0, 0.0, 0.5), piece(2.5, 0.2, 0.3, 0.1, 0.5), piece(1.0, 0.0, 0.0, 0.0, 0.5, -0.3), piece(3.0, 0.0, 0.5, 0.0, 0.5)}));
    const InterpolationRoots roots = rootsOnLine(Vec3d(0, 0, 0), Vec3d(1, 0, 0), 41);
    HelicoidInterpolationParams most;
    most.pieceCount = PieceCountRule::Most;  // the rule without a jump (the default keeps the heaviest's pieces)
    const Scene interp = interpolateHelicoids(scene, roots, most);
    for (std::size_t i = 1; i + 1 < interp.guides.size(); ++i) {
        const SceneGuide& g = interp.guides[i];
        REQUIRE(g.pieces.size() == 4u);
        HelicoidTrace trace;
        tracePHelicoid(g.root, g.frame, g.pieces, scene.step, HelicoidIntegrator::Euler, trace);
        for (std::size_t j = 1; j < trace.pieces.size(); ++j) {
            const std::size_t at = trace.joints[j];
            const Helicoid& prev = trace.pieces[j - 1];
            const FrameD end = prev.frameFromTheta(prev.theta(trace.points[at], 0.0));
            // The next piece starts with the previous piece's end frame (Eq. 2), rolled about its tangent.
            CAPTURE(i, j);
            REQUIRE((trace.pieces[j].q.t - end.t).length() < 1e-9);
            REQUIRE(std::abs(trace.pieces[j].q.n.dot(end.t)) < 1e-9);
        }
    }
    // Neighbouring interpolants stay close (no jump in the piece structure between the guides).
    const StrandSet s = growScene(interp);
    double worstStep = 0.0;
    for (std::size_t i = 1; i + 2 < roots.positions.size(); ++i) {
        const std::vector<double> a = curvatureProfile(s, i), b = curvatureProfile(s, i + 1);
        std::vector<Vec3f> ra(31), rb(31);
        resamplePolyline(s.positions.data() + s.begin(i), s.size(i), 31, ra.data());
        resamplePolyline(s.positions.data() + s.begin(i + 1), s.size(i + 1), 31, rb.data());
        for (int v = 0; v < 31; ++v) worstStep = std::max(worstStep, double((rb[v] - rb[0] - (ra[v] - ra[0])).length()));
    }
    CAPTURE(worstStep);
    REQUIRE(worstStep < 0.15);  // 40 steps across: ~0.025 of the root spacing per step at 2 units of length
}

TEST_CASE("interpolateHelicoids and interpolatePoints: identical for 1 and 2 threads", "[helicoid][interp]")
{
    Scene scene;
    scene.step = 0.02;
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (int g = 0; g < 9; ++g) {
        std::vector<HelicoidPiece> pcs;
        for (int p = 0; p < 2 + g % 3; ++p) pcs.push_back(piece(2.0 * u(rng), u(rng), u(rng), u(rng), 0.5, u(rng)));
        scene.guides.push_back(makeGuide(Vec3d(u(rng), u(rng), 0.0), kUp.rolled(u(rng)), pcs));
    }
    InterpolationRoots roots;
    for (int i = 0; i < 3000; ++i) roots.positions.emplace_back(u(rng), u(rng), 0.0);
    StrandSet h[2], p[2];
    for (int t = 0; t < 2; ++t) {
        tbb::global_control c(tbb::global_control::max_allowed_parallelism, std::size_t(t + 1));
        h[t] = growScene(interpolateHelicoids(scene, roots, {}));
        p[t] = interpolatePoints(growScene(scene), roots, {});
    }
    REQUIRE(h[0].offsets == h[1].offsets);
    REQUIRE(h[0].positions == h[1].positions);
    REQUIRE(p[0].offsets == p[1].offsets);
    REQUIRE(p[0].positions == p[1].positions);
}

TEST_CASE("interpolation: bad input is refused before any work, naming the value and the rule", "[helicoid][interp]")
{
    Scene scene;
    scene.guides.push_back(makeGuide(Vec3d(0, 0, 0), kUp, {piece(1.0, 0.0, 0.0, 0.0, 1.0)}));
    const InterpolationRoots roots = rootsOnLine(Vec3d(0, 0, 0), Vec3d(1, 0, 0), 3);
    Scene none;
    REQUIRE_THROWS_WITH(interpolateHelicoids(none, roots, {}), Contains("no guides"));
    Scene zero = scene;
    zero.guides[0].pieces[0].length = 0.0;
    REQUIRE_THROWS_WITH(interpolateHelicoids(zero, roots, {}), Contains("guide 0: zero length"));
    Scene nan = scene;
    nan.guides[0].pieces[0].k.kB = std::nan("");
    REQUIRE_THROWS_WITH(interpolateHelicoids(nan, roots, {}), Contains("guide 0: piece 0: k is not finite"));
    HelicoidInterpolationParams bad;
    bad.shepard.power = 0.0;
    REQUIRE_THROWS_WITH(interpolateHelicoids(scene, roots, bad), Contains("power 0: must be a positive"));
    bad = {};
    bad.shepard.neighbors = 0;
    REQUIRE_THROWS_WITH(interpolateHelicoids(scene, roots, bad), Contains("neighbors 0: must be at least 1"));
    bad = {};
    bad.maxVertices = 100;
    REQUIRE_THROWS_AS(interpolateHelicoids(scene, roots, bad), LimitError);
    PointInterpolationParams pbad;
    pbad.neighbors = 0;
    REQUIRE_THROWS_WITH(interpolatePoints(growScene(scene), roots, pbad), Contains("neighbors 0"));
    StrandSet flat;
    flat.addStrand(std::vector<Vec3f>{Vec3f(0.f), Vec3f(0.f)});
    REQUIRE_THROWS_WITH(interpolatePoints(flat, roots, {}), Contains("zero length"));
}

TEST_CASE("interpolateHelicoids: next to a guide's root the blend approaches that guide (the general path)", "[helicoid][interp]")
{
    const Scene scene = twoSpatialGuides(0.01);
    const StrandSet guides = growScene(scene);
    InterpolationRoots near;
    near.positions.push_back(Vec3d(1e-4, 0, 0));  // weight of the other guide ~1e-12
    const StrandSet s = growScene(interpolateHelicoids(scene, near, {}));
    REQUIRE(s.size(0) == guides.size(0));
    float worst = 0.f;
    for (std::size_t v = 0; v < s.size(0); ++v) worst = std::max(worst, (s.positions[v] - Vec3f(1e-4f, 0.f, 0.f) - guides.positions[v]).length());
    REQUIRE(worst < 1e-5f);
}

namespace {

/// The largest distance between strand @a i of @a a and strand @a j of @a b (moved by @a shift),
/// both resampled to 201 points by arc length.
double curveDistance(const StrandSet& a, std::size_t i, const StrandSet& b, std::size_t j, const Vec3f& shift = Vec3f(0.f))
{
    std::vector<Vec3f> ra(201), rb(201);
    resamplePolyline(a.positions.data() + a.begin(i), a.size(i), ra.size(), ra.data());
    resamplePolyline(b.positions.data() + b.begin(j), b.size(j), rb.size(), rb.data());
    double worst = 0.0;
    for (std::size_t k = 0; k < ra.size(); ++k) worst = std::max(worst, double((ra[k] - rb[k] - shift).length()));
    return worst;
}

HelicoidInterpolationParams arcsParams()
{
    HelicoidInterpolationParams p;
    p.blend = HelicoidBlend::Arcs;
    return p;
}

} // namespace

TEST_CASE("interpolateHelicoids, arcs: next to a guide's root the blend follows that guide's curve", "[helicoid][interp]")
{
    // Three-dimensional p-helicoids (alpha, kN, kB and rolls): the arcs describe the curve, not its pieces.
    const Scene scene = twoSpatialGuides(0.005);
    const StrandSet guides = growScene(scene);
    InterpolationRoots near;
    near.positions.push_back(Vec3d(1e-4, 0, 0));  // weight of the other guide ~1e-12: the general path
    const Scene out = interpolateHelicoids(scene, near, arcsParams());
    REQUIRE(out.guides[0].pieces.size() >= 16);  // one arc per 0.2 radian of the most-turning guide, at least 16
    for (const HelicoidPiece& p : out.guides[0].pieces) {
        REQUIRE(p.k.kT >= 0.0);
        REQUIRE(p.k.kN == 0.0);
        REQUIRE(p.k.kB == 0.0);
        REQUIRE(p.k.alpha == 0.0);
    }
    const StrandSet s = growScene(out);
    const double d = curveDistance(s, 0, guides, 0, Vec3f(1e-4f, 0.f, 0.f));
    CAPTURE(d, out.guides[0].pieces.size());
    REQUIRE(d < 5e-3 * 2.5);  // within 0.5 % of the guide's length of 2.5 (0.22 % measured, 16 arcs)
    // More arcs follow it more closely.
    HelicoidInterpolationParams fine = arcsParams();
    fine.arcs = 4 * out.guides[0].pieces.size();
    const double dFine = curveDistance(growScene(interpolateHelicoids(scene, near, fine)), 0, guides, 0, Vec3f(1e-4f, 0.f, 0.f));
    CAPTURE(dFine);
    REQUIRE(dFine < 0.25 * d);
}

TEST_CASE("interpolateHelicoids, arcs: guides of one curve described unlike each other blend into that curve", "[helicoid][interp]")
{
    // Three guides with the same curve: one piece; the kT sign flipped with its frame turned by π;
    // and three pieces of the same k (each restarts the helicoid at its joint, so it is another
    // curve unless k is a pure circle: kT only). Fitted pieces of different counts do not blend
    // (PieceCountRule); their arcs are alike, so every blend is the curve itself.
    Scene scene;
    scene.step = 0.005;
    scene.integrator = HelicoidIntegrator::RK4;
    const FrameD q = FrameD::fromTangentNormal(Vec3d(0.2, 0.1, 1.0), Vec3d(1, 0, 0));
    scene.guides.push_back(makeGuide(Vec3d(0, 0, 0), q, {piece(1.2, 0, 0, 0, 2.4)}));
    scene.guides.push_back(makeGuide(Vec3d(1, 0, 0), q.rolled(M_PI), {piece(-1.2, 0, 0, 0, 2.4)}));
    scene.guides.push_back(makeGuide(Vec3d(0, 1, 0), q, {piece(1.2, 0, 0, 0, 0.8), piece(1.2, 0, 0, 0, 0.8), piece(1.2, 0, 0, 0, 0.8)}));
    const StrandSet guides = growScene(scene);
    REQUIRE(curveDistance(guides, 1, guides, 0, Vec3f(1.f, 0.f, 0.f)) < 1e-5);
    REQUIRE(curveDistance(guides, 2, guides, 0, Vec3f(0.f, 1.f, 0.f)) < 1e-5);
    InterpolationRoots roots;
    for (const Vec3d& r : {Vec3d(0.4, 0.3, 0), Vec3d(0.5, 0.5, 0), Vec3d(0.2, 0.7, 0)}) roots.positions.push_back(r);
    const StrandSet s = growScene(interpolateHelicoids(scene, roots, arcsParams()));
    for (std::size_t i = 0; i < 3; ++i) {
        const double d = curveDistance(s, i, guides, 0, Vec3f(roots.positions[i]));
        CAPTURE(i, d);
        REQUIRE(d < 2e-3 * 2.4);
    }
}

TEST_CASE("interpolateHelicoids, arcs: hair does not blend across a parting", "[helicoid][interp]")
{
    // Two guides leaving the scalp 40° apart and bending to opposite sides (a parting between
    // them): blended, their bends would cancel into a hair that sticks out. Shaped unlike each
    // other (mean distance far above a quarter of the length), only the heaviest takes part.
    Scene scene;
    scene.step = 0.01;
    scene.integrator = HelicoidIntegrator::RK4;
    const FrameD left = FrameD::fromTangentNormal(Vec3d(-0.34, 0, 0.94), Vec3d(-1, 0, 0));
    const FrameD right = FrameD::fromTangentNormal(Vec3d(0.34, 0, 0.94), Vec3d(1, 0, 0));
    scene.guides.push_back(makeGuide(Vec3d(0, 0, 0), left, {piece(1.0, 0, 0, 0, 3.0)}));
    scene.guides.push_back(makeGuide(Vec3d(1, 0, 0), right, {piece(1.0, 0, 0, 0, 3.0)}));
    const StrandSet guides = growScene(scene);
    InterpolationRoots roots;
    roots.positions = {Vec3d(0.4, 0, 0), Vec3d(0.6, 0, 0)};
    const StrandSet s = growScene(interpolateHelicoids(scene, roots, arcsParams()));
    CAPTURE(curveDistance(s, 0, guides, 0, Vec3f(0.4f, 0.f, 0.f)), curveDistance(s, 1, guides, 1, Vec3f(-0.4f, 0.f, 0.f)));
    REQUIRE(curveDistance(s, 0, guides, 0, Vec3f(0.4f, 0.f, 0.f)) < 0.01 * 3.0);
    REQUIRE(curveDistance(s, 1, guides, 1, Vec3f(-0.4f, 0.f, 0.f)) < 0.01 * 3.0);
}

namespace {

/// A parting along x = 0: guides at x in [-1, 1] rise 1 along y, then sweep 1 along -x (left of
/// the parting) or +x (right of it), 12 vertices each.
StrandSet partedGuides(int count)
{
    StrandSet g;
    for (int i = 0; i < count; ++i) {
        const float x = -1.f + 2.f * float(i) / float(count - 1) + 0.013f;  // none exactly on the parting
        const float side = x < 0.f ? -1.f : 1.f;
        std::vector<Vec3f> p;
        for (int k = 0; k < 6; ++k) p.emplace_back(x, 0.2f * float(k), 0.f);
        for (int k = 1; k <= 6; ++k) p.emplace_back(x + side * 0.2f * float(k), 1.f, 0.f);
        g.addStrand(p);
    }
    return g;
}

} // namespace

TEST_CASE("interpolatePoints: a parting stays a parting with shape grouping, and spikes without", "[helicoid][interp]")
{
    const StrandSet guides = partedGuides(21);
    InterpolationRoots roots;
    for (int i = 0; i <= 200; ++i) roots.positions.emplace_back(-0.9 + 1.8 * i / 200.0, 0.0, 0.0);
    const StrandSet grouped = interpolatePoints(guides, roots, {});
    PointInterpolationParams none;
    none.grouping = GuideGrouping::None;
    const StrandSet blended = interpolatePoints(guides, roots, none);
    std::vector<Vec3d> guideRoots;
    for (std::size_t g = 0; g < guides.numStrands(); ++g) guideRoots.emplace_back(guides.root(g).x(), 0.0, 0.0);
    const GuideLocator locator(guideRoots);
    double weakestSweep = 1e9, weakestBlended = 1e9;
    for (std::size_t i = 0; i < roots.positions.size(); ++i) {
        CAPTURE(i, roots.positions[i].x());
        const std::uint32_t nearest = locator.nearest(roots.positions[i]);
        const float side = guides.positions[guides.begin(nearest) + 11].x() - guides.root(nearest).x();
        const float sweep = grouped.positions[grouped.begin(i) + grouped.size(i) - 1].x() - grouped.root(i).x();
        REQUIRE(sweep * side > 0.f);  // the side of the nearest guide
        weakestSweep = std::min(weakestSweep, double(std::abs(sweep)));
        weakestBlended = std::min(weakestBlended, double(std::abs(blended.positions[blended.begin(i) + blended.size(i) - 1].x() - blended.root(i).x())));
    }
    CAPTURE(weakestSweep, weakestBlended);
    CHECK(weakestSweep == Approx(1.2).margin(1e-4));  // every new hair sweeps as its guides: 1.2 = 6 x 0.2
    CHECK(weakestBlended < 0.3);                       // distance alone averages the two sweeps away at the parting
    REQUIRE(likenessDistance(guides.positions.data(), 12, guides.positions.data() + guides.begin(20), 12) > 0.25);
    REQUIRE(likenessDistance(guides.positions.data(), 12, guides.positions.data() + guides.begin(1), 12) == Approx(0.0).margin(1e-6));
}

TEST_CASE("interpolatePoints: explicit groups, and a root on a guide's root is that guide bit for bit", "[helicoid][interp]")
{
    const StrandSet guides = partedGuides(21);
    GuideContext context;
    for (std::size_t g = 0; g < guides.numStrands(); ++g) context.groups.push_back(guides.root(g).x() < 0.f ? 3 : 8);
    InterpolationRoots roots;
    for (int i = 0; i <= 20; ++i) roots.positions.emplace_back(-0.9 + 1.8 * i / 20.0, 0.0, 0.0);
    roots.groups.assign(roots.positions.size(), 8);  // every root on the right side's group
    PointInterpolationParams none;
    none.grouping = GuideGrouping::None;  // groups alone decide
    std::size_t groups = 0;
    const StrandSet out = interpolatePoints(guides, roots, none, context, true, nullptr, &groups);
    CHECK(groups == 2);
    for (std::size_t i = 0; i < out.numStrands(); ++i) {
        CAPTURE(i);
        REQUIRE(out.positions[out.begin(i) + out.size(i) - 1].x() - out.root(i).x() == Approx(1.2f).margin(1e-4));
    }
    // Roots on the guides' roots reproduce the guides exactly.
    InterpolationRoots own;
    for (std::size_t g = 0; g < guides.numStrands(); ++g) own.positions.emplace_back(guides.root(g).x(), guides.root(g).y(), guides.root(g).z());
    const StrandSet same = interpolatePoints(guides, own, {}, context);
    REQUIRE(same.offsets == guides.offsets);
    REQUIRE(same.positions == guides.positions);
    // Bad groups: refused, naming the count or the group.
    roots.groups[4] = 5;
    REQUIRE_THROWS_WITH(interpolatePoints(guides, roots, {}, context), Contains("root 4: group 5 has no guides"));
    roots.groups.pop_back();
    REQUIRE_THROWS_WITH(interpolatePoints(guides, roots, {}, context), Contains("20 root group ids for 21 roots"));
    context.groups.pop_back();
    REQUIRE_THROWS_WITH(interpolatePoints(guides, own, {}, context), Contains("20 guide group ids for 21 guides"));
    PointInterpolationParams bad;
    bad.likeness = 0.0;
    REQUIRE_THROWS_WITH(interpolatePoints(guides, own, bad), Contains("likeness 0: must be a positive"));
}

TEST_CASE("interpolateGuides: new hair is kept out of the head, both methods", "[helicoid][interp]")
{
    // Guides on a unit sphere's top cap, combed flat along +x: they follow the sphere at 0.02 above it.
    StrandSet guides;
    for (int i = 0; i < 9; ++i) {
        const double phi = -0.4 + 0.1 * i;
        std::vector<Vec3f> p;
        for (int k = 0; k < 16; ++k) {
            const double t = 0.08 * k;  // angle along the sphere from the top, towards +x
            p.emplace_back(float(1.02 * std::sin(t) * std::cos(phi)), float(1.02 * std::cos(t)), float(1.02 * std::sin(phi)));
        }
        guides.addStrand(p);
    }
    const HeadObstacle head = HeadObstacle::sphere(Vec3d(0.0), 1.0);
    REQUIRE(countStrandsEnteringHead(guides, head, 0.0) == 0);
    // Roots off the guides' line, where their translated shapes cut into the sphere.
    InterpolationRoots roots;
    for (int i = 0; i < 50; ++i) {
        const double t = -0.3 + 0.012 * i;
        roots.positions.emplace_back(1.02 * std::sin(t), 1.02 * std::cos(t), 0.05);
    }
    InterpolationGuides g;
    g.strands = &guides;
    for (InterpolationMethod method : {InterpolationMethod::Points, InterpolationMethod::Helicoid}) {
        CAPTURE(interpolationMethodName(method));
        InterpolateParams params;
        params.method = method;
        const InterpolateResult free = interpolateGuides(g, roots, HeadObstacle::none(), params);
        CHECK(countStrandsEnteringHead(free.strands, head, 0.0) > 10);
        CHECK(free.pushedOut == 0);
        const InterpolateResult kept = interpolateGuides(g, roots, head, params);
        CHECK(kept.enteringHead == 0);
        CHECK(countStrandsEnteringHead(kept.strands, head, 0.0) == 0);
        CHECK(kept.pushedOut > 10);
        CHECK(kept.verticesTooDeep == 0);
        CHECK(kept.guidesEnteringHead == 0);
    }
}

TEST_CASE("interpolatePoints: each new strand's binding is its three guides of largest weight, summing to 1", "[helicoid][interp]")
{
    // Five straight guides on a line; a root on a guide's root is that guide alone, a root between
    // two blends them most, and the binding lists guides by weight (largest first).
    StrandSet guides;
    for (int g = 0; g < 5; ++g) guides.addStrand({Vec3f(float(g), 0, 0), Vec3f(float(g), 1, 0)});
    InterpolationRoots roots;
    roots.positions = {Vec3d(2, 0, 0), Vec3d(0.5, 0, 0), Vec3d(3.25, 0, 0)};
    PointInterpolationParams params;
    params.grouping = GuideGrouping::None;
    GuideBinding b;
    interpolatePoints(guides, roots, params, {}, true, nullptr, nullptr, nullptr, &b);
    REQUIRE(b.guides.size() == 9);
    REQUIRE(b.weights.size() == 9);
    CHECK(b.guides[0] == 2);
    CHECK(b.weights[0] == 1.0f);
    CHECK(b.weights[1] == 0.0f);
    for (std::size_t i = 0; i < 3; ++i) {
        CHECK(b.weights[3 * i] + b.weights[3 * i + 1] + b.weights[3 * i + 2] == Approx(1.0).epsilon(1e-6));
        CHECK(b.weights[3 * i] >= b.weights[3 * i + 1]);
        CHECK(b.weights[3 * i + 1] >= b.weights[3 * i + 2]);
    }
    CHECK(((b.guides[3] == 0 && b.guides[4] == 1) || (b.guides[3] == 1 && b.guides[4] == 0)));
    CHECK(b.weights[3] == Approx(b.weights[4]).epsilon(1e-6));  // midway: the two alike
    CHECK(b.guides[6] == 3);  // nearer 3 than 4
    CHECK(b.guides[7] == 4);
    // The same for one thread.
    GuideBinding one;
    {
        tbb::global_control c(tbb::global_control::max_allowed_parallelism, 1);
        interpolatePoints(guides, roots, params, {}, true, nullptr, nullptr, nullptr, &one);
    }
    CHECK(one.guides == b.guides);
    CHECK(one.weights == b.weights);
}
