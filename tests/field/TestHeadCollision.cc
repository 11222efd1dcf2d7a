#include <vdbhair/Exceptions.h>
#include <vdbhair/field/HeadCollision.h>
#include <vdbhair/scalp/HeadFile.h>
#include <vdbhair/strands/Measures.h>

#include "../TestUtil.h"

#include <catch2/catch.hpp>

#include <openvdb/tools/LevelSetSphere.h>

#include <tbb/global_control.h>

#include <cmath>
#include <random>
#include <vector>

using namespace vdbhair;
using Catch::Matchers::Contains;

namespace {

/// A straight strand of @a n vertices from @a root along @a dir, @a length long.
std::vector<Vec3f> line(const Vec3f& root, Vec3f dir, float length, int n)
{
    dir.normalize();
    std::vector<Vec3f> p;
    for (int k = 0; k < n; ++k) p.push_back(root + dir * (length * float(k) / float(n - 1)));
    return p;
}

/// The largest turning angle between consecutive segments of strand @a i (radians).
double maxTurn(const StrandSet& s, std::size_t i)
{
    double worst = 0.0;
    for (std::size_t k = 1; k + 1 < s.size(i); ++k) {
        Vec3f a = s.positions[s.begin(i) + k] - s.positions[s.begin(i) + k - 1];
        Vec3f b = s.positions[s.begin(i) + k + 1] - s.positions[s.begin(i) + k];
        const double c = std::clamp(double(a.dot(b)) / (double(a.length()) * double(b.length())), -1.0, 1.0);
        worst = std::max(worst, std::acos(c));
    }
    return worst;
}

/// The summed turning angles of strand @a i (radians).
double totalTurn(const StrandSet& s, std::size_t i)
{
    double sum = 0.0;
    for (std::size_t k = 1; k + 1 < s.size(i); ++k) {
        const Vec3d a(s.positions[s.begin(i) + k] - s.positions[s.begin(i) + k - 1]);
        const Vec3d b(s.positions[s.begin(i) + k + 1] - s.positions[s.begin(i) + k]);
        sum += std::acos(std::clamp(a.dot(b) / (a.length() * b.length()), -1.0, 1.0));
    }
    return sum;
}

} // namespace

TEST_CASE("resolveHeadCollisions: strands through a sphere come out smoothly, at their length, roots fixed", "[field]")
{
    const HeadObstacle head = HeadObstacle::sphere(Vec3d(0.0), 1.0);
    StrandSet s;
    // From the top of the unit sphere, aimed 10-60 degrees below the horizon: each would cut through it.
    for (int j = 0; j < 6; ++j) {
        const double a = (10.0 + 10.0 * j) * M_PI / 180.0;
        s.addStrand(line(Vec3f(0.f, 1.f, 0.f), Vec3f(float(std::cos(a)), -float(std::sin(a)), 0.1f * float(j)), 3.f, 61));
    }
    const StrandSet before = s;
    REQUIRE(countStrandsEnteringHead(s, head, 0.0) == 6);
    const HeadCollisionStats stats = resolveHeadCollisions(s, head, {});
    CHECK(stats.strandsMoved == 6);
    CHECK(stats.verticesTooDeep == 0);
    CHECK(countStrandsEnteringHead(s, head, 0.0) == 0);
    HeadObstacle::Probe probe(head);
    for (std::size_t i = 0; i < s.numStrands(); ++i) {
        CAPTURE(i);
        REQUIRE(s.root(i) == before.root(i));
        for (std::size_t k = 0; k < s.size(i); ++k) {
            const Vec3f& p = s.positions[s.begin(i) + k];
            REQUIRE(probe.distance(Vec3d(p.x(), p.y(), p.z())) >= -1e-6);
        }
        CHECK(polylineLength(s.positions.data() + s.begin(i), s.size(i)) ==
              Approx(polylineLength(before.positions.data() + before.begin(i), before.size(i))).epsilon(0.02));
        // Spread over the strand: no bend at one vertex like a per-vertex push (a straight strand
        // hitting a unit sphere needs about 90 degrees in all over its 60 segments).
        CHECK(maxTurn(s, i) < 25.0 * M_PI / 180.0);
    }
}

TEST_CASE("resolveHeadCollisions: coarse strands aimed steeply into a sphere come out without a kink", "[field]")
{
    // 16 vertices a strand (TressFX guides, cyHair's straight.hair): a strand meeting the head at
    // up to 80 degrees must turn that much, and a sweep alone turns it at one vertex. Seeded random
    // roots on the upper half of the unit sphere, directions 20-80 degrees into it, 1-4 radii long.
    const HeadObstacle head = HeadObstacle::sphere(Vec3d(0.0), 1.0);
    std::mt19937 rng(49);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    StrandSet s;
    for (int j = 0; j < 300; ++j) {
        const double phi = 2.0 * M_PI * u(rng), theta = 0.5 * M_PI * u(rng);
        const Vec3d n(std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi));
        Vec3d t = Vec3d(0.0, 1.0, 0.0).cross(n);
        if (t.length() < 1e-3) t = Vec3d(1.0, 0.0, 0.0);
        t.normalize();
        t = t * std::cos(2.0 * M_PI * u(rng)) + n.cross(t) * std::sin(2.0 * M_PI * u(rng));
        t.normalize();
        const double into = (20.0 + 60.0 * u(rng)) * M_PI / 180.0;
        const Vec3d dir = t * std::cos(into) - n * std::sin(into);
        s.addStrand(line(Vec3f(n * 1.001), Vec3f(dir), float(1.0 + 3.0 * u(rng)), 16));
    }
    const StrandSet before = s;
    REQUIRE(countStrandsEnteringHead(s, head, 0.0) == s.numStrands());
    const HeadCollisionStats stats = resolveHeadCollisions(s, head, {});
    CHECK(stats.strandsMoved == s.numStrands());
    CHECK(stats.verticesTooDeep == 0);
    HeadObstacle::Probe probe(head);
    double worst = 0.0;
    for (std::size_t i = 0; i < s.numStrands(); ++i) {
        CAPTURE(i);
        REQUIRE(s.root(i) == before.root(i));
        for (std::size_t k = 0; k < s.size(i); ++k) REQUIRE(probe.distance(Vec3d(s.positions[s.begin(i) + k])) >= -1e-6);
        for (std::size_t k = 1; k < s.size(i); ++k) {
            const double la = double((before.positions[before.begin(i) + k] - before.positions[before.begin(i) + k - 1]).length());
            const double lb = double((s.positions[s.begin(i) + k] - s.positions[s.begin(i) + k - 1]).length());
            REQUIRE(lb == Approx(la).epsilon(1e-4));
        }
        worst = std::max(worst, maxTurn(s, i));
    }
    INFO("largest turn between two segments: " << worst * 180.0 / M_PI << " degrees");
    CHECK(worst < 45.0 * M_PI / 180.0);
    // The same on one thread.
    StrandSet one = before;
    resolveHeadCollisions(one, head, {}, {}, false);
    CHECK(one.positions == s.positions);
}

TEST_CASE("resolveHeadCollisions: a curly strand pushed out keeps its curls", "[field]")
{
    // A helix of radius 0.05 and pitch 0.1 around an axis aimed 45 degrees into the unit sphere:
    // the push-out moves the curls as a whole (smoothing displacements, not positions), so each
    // strand's turning stays within 10 % of its own.
    const HeadObstacle head = HeadObstacle::sphere(Vec3d(0.0), 1.0);
    StrandSet s;
    for (int j = 0; j < 8; ++j) {
        const double phi = 2.0 * M_PI * j / 8.0;
        const Vec3d n(0.5 * std::cos(phi), std::sqrt(0.75), 0.5 * std::sin(phi));
        Vec3d t = Vec3d(-std::sin(phi), 0.0, std::cos(phi));
        const Vec3d axis = (t - n).unit(), b1 = t.cross(n).unit(), b2 = axis.cross(b1).unit();
        std::vector<Vec3f> p;
        for (int k = 0; k < 120; ++k) {
            const double a = 0.025 * k;  // 3 units along the axis
            const double w = 2.0 * M_PI * a / 0.1;
            p.emplace_back(n * 1.06 + axis * a + (b1 * (std::cos(w) - 1.0) + b2 * std::sin(w)) * 0.05);
        }
        s.addStrand(p);
    }
    const StrandSet before = s;
    REQUIRE(countStrandsEnteringHead(s, head, 0.0) == s.numStrands());
    resolveHeadCollisions(s, head, {});
    CHECK(countStrandsEnteringHead(s, head, 0.0) == 0);
    for (std::size_t i = 0; i < s.numStrands(); ++i) {
        const double ta = totalTurn(before, i), tb = totalTurn(s, i);
        CAPTURE(i, ta, tb);
        CHECK(tb == Approx(ta).epsilon(0.1));
    }
}

TEST_CASE("resolveHeadCollisions: under HeadDepthRule::Rising new hair rises out of the scalp and does not dive back", "[field]")
{
    // Rooted 0.1 inside the unit sphere; each strand runs along the surface, dips deeper, then leaves.
    const HeadObstacle head = HeadObstacle::sphere(Vec3d(0.0), 1.0);
    StrandSet s;
    for (int j = 0; j < 12; ++j) {
        const double phi = 2.0 * M_PI * j / 12.0;
        std::vector<Vec3f> p;
        for (int k = 0; k < 24; ++k) {
            const double a = 0.06 * k;  // angle from the top along the great circle through phi
            const double r = 0.9 - 0.15 * std::sin(M_PI * std::min(1.0, a / 0.8)) + (a > 0.8 ? 0.5 * (a - 0.8) : 0.0);
            p.emplace_back(Vec3d(std::sin(a) * std::cos(phi), std::cos(a), std::sin(a) * std::sin(phi)) * r);
        }
        s.addStrand(p);
    }
    const StrandSet before = s;
    HeadCollisionParams rising;
    rising.depthRule = HeadDepthRule::Rising;
    // The root's depth allowed everywhere (rootDepthAllowance()): the dip is allowed...
    const std::vector<float> allowed = rootDepthAllowance(s, head);
    StrandSet asAllowed = s;
    CHECK(resolveHeadCollisions(asAllowed, head, allowed).strandsMoved == s.numStrands());
    // ...but not under Rising: no vertex deeper than one before it (to the bisection's 1e-4 of a segment).
    CHECK(resolveHeadCollisions(s, head, allowed, rising).strandsMoved == s.numStrands());
    HeadObstacle::Probe probe(head);
    std::size_t insideBefore = 0, insideAfter = 0;
    for (std::size_t i = 0; i < s.numStrands(); ++i) {
        CAPTURE(i);
        REQUIRE(s.root(i) == before.root(i));
        double shallowest = probe.distance(Vec3d(s.root(i)));
        for (std::size_t k = 1; k < s.size(i); ++k) {
            const double d = probe.distance(Vec3d(s.positions[s.begin(i) + k]));
            CAPTURE(k, d, shallowest);
            CHECK(d >= std::min(0.0, shallowest) - 1e-4);
            shallowest = std::max(shallowest, d);
            insideAfter += d < 0.0;
            insideBefore += probe.distance(Vec3d(before.positions[before.begin(i) + k])) < 0.0;
        }
        CHECK(maxTurn(s, i) < 45.0 * M_PI / 180.0);
    }
    CHECK(insideAfter < insideBefore);
}

TEST_CASE("resolveHeadCollisions: an allowance keeps strands as deep as allowed, and leaves others alone", "[field]")
{
    const HeadObstacle head = HeadObstacle::sphere(Vec3d(0.0), 1.0);
    StrandSet s;
    s.addStrand(line(Vec3f(0.f, 0.9f, 0.f), Vec3f(1.f, 0.f, 0.f), 2.f, 21));   // starts 0.1 deep, leaves the sphere
    s.addStrand(line(Vec3f(0.f, 1.5f, 0.f), Vec3f(0.f, 1.f, 0.f), 2.f, 21));   // outside everywhere
    const StrandSet before = s;
    // 0.1 deep allowed everywhere: the first strand is only ever shallower than its root, nothing moves.
    std::vector<float> allowed(s.numVertices(), 0.1f);
    StrandSet same = s;
    CHECK(resolveHeadCollisions(same, head, allowed).strandsMoved == 0);
    CHECK(same.positions == before.positions);
    // Outside everywhere: the first strand moves, the second does not.
    const HeadCollisionStats stats = resolveHeadCollisions(s, head, {});
    CHECK(stats.strandsMoved == 1);
    for (std::size_t k = 0; k < s.size(1); ++k) CHECK(s.positions[s.begin(1) + k] == before.positions[before.begin(1) + k]);
    REQUIRE_THROWS_WITH(resolveHeadCollisions(s, head, std::vector<float>(3, 0.f)), Contains("3 allowed depths for 42 vertices"));
    REQUIRE_THROWS_WITH(resolveHeadCollisions(s, head, std::vector<float>(42, -1.f)), Contains("must be finite and non-negative"));
}

TEST_CASE("resolveHeadCollisions: identical for 1 and 2 threads", "[field]")
{
    const HeadObstacle head = HeadObstacle::sphere(Vec3d(0.0), 1.0);
    StrandSet s;
    for (int j = 0; j < 2000; ++j) {
        const double a = 2.0 * M_PI * j / 2000.0;
        // From the unit circle, along its tangent and a little inwards: each cuts into the sphere.
        const Vec3f radial(float(std::cos(a)), float(std::sin(a)), 0.f), tangent(-float(std::sin(a)), float(std::cos(a)), 0.f);
        s.addStrand(line(radial, tangent - 0.3f * radial + Vec3f(0.f, 0.f, 0.2f * float(j % 7 - 3)), 2.f, 24));
    }
    StrandSet r[2] = {s, s};
    for (int t = 0; t < 2; ++t) {
        tbb::global_control c(tbb::global_control::max_allowed_parallelism, std::size_t(t + 1));
        resolveHeadCollisions(r[t], head, {});
    }
    REQUIRE(r[0].positions == r[1].positions);
    REQUIRE(countStrandsEnteringHead(s, head, 0.0) == s.numStrands());
    REQUIRE(countStrandsEnteringHead(r[0], head, 0.0) == 0);
}

TEST_CASE("HeadObstacle::Probe::distance with its direction: the trilinear cell's value and gradient on a level-set sphere", "[field]")
{
    openvdb::FloatGrid::Ptr grid = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(1.0f, openvdb::Vec3f(0.2f, -0.1f, 0.3f), 0.05f, 3.0f);
    grid->setGridClass(openvdb::GRID_LEVEL_SET);
    const HeadObstacle head = HeadObstacle::levelSet(grid);
    HeadObstacle::Probe probe(head);
    std::mt19937 rng(4);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (int i = 0; i < 500; ++i) {
        Vec3d dir(u(rng), u(rng), u(rng));
        if (dir.length() < 1e-3) continue;
        dir.normalize();
        const Vec3d p = Vec3d(0.2, -0.1, 0.3) + dir * (1.0 + 0.08 * u(rng));  // within the band
        Vec3d g;
        const double d = probe.distance(p, g);
        CAPTURE(i, p);
        CHECK(d == Approx(probe.distance(p)).margin(1e-6));
        CHECK(d == Approx((p - Vec3d(0.2, -0.1, 0.3)).length() - 1.0).margin(0.01));
        CHECK(g.length() == Approx(1.0).margin(1e-9));
        CHECK(g.dot(dir) > std::cos(5.0 * M_PI / 180.0));  // radial within 5 degrees at 20 voxels a radius
    }
}

TEST_CASE("resolveHeadCollisions: a strand driven head-on into Sintel's head slides along it, not back and forth", "[field][data]")
{
    VDBHAIR_REQUIRE_SHARED_DATA();
    // A strand `synth` made from Sintel's hair (seed 0) that runs from the temple into the head
    // near the ear, 0.6 deep for most of its length. The sweep turned each deep vertex the way its
    // own point's normal tilted; there the normals of consecutive points tilt opposite ways, and the
    // strand zigzagged between two points with turns of 150-180 degrees between its edges.
    const HeadObstacle head = readHeadObstacle(test::sharedData() + "/scalp/sintel/sintel.obj", "test");
    StrandSet s;
    s.addStrand(std::vector<Vec3f>{
        {-8.647f, 33.488f, 0.803f}, {-8.590f, 33.330f, 0.729f}, {-8.533f, 33.172f, 0.655f}, {-8.476f, 33.014f, 0.581f},
        {-8.419f, 32.856f, 0.507f}, {-8.361f, 32.699f, 0.432f}, {-8.304f, 32.541f, 0.358f}, {-8.227f, 32.396f, 0.277f},
        {-8.148f, 32.251f, 0.195f}, {-8.070f, 32.106f, 0.114f}, {-7.992f, 31.961f, 0.033f}, {-7.913f, 31.817f,
        -0.049f}, {-7.835f, 31.672f, -0.130f}, {-7.752f, 31.531f, -0.213f}, {-7.668f, 31.390f, -0.296f}, {-7.564f,
        31.270f, -0.386f}, {-7.455f, 31.154f, -0.478f}, {-7.345f, 31.039f, -0.570f}, {-7.236f, 30.923f, -0.661f},
        {-7.126f, 30.808f, -0.753f}, {-7.016f, 30.693f, -0.844f}, {-6.906f, 30.579f, -0.937f}, {-6.794f, 30.467f,
        -1.031f}, {-6.675f, 30.373f, -1.132f}, {-6.551f, 30.286f, -1.237f}, {-6.428f, 30.200f, -1.342f}, {-6.305f,
        30.114f, -1.447f}, {-6.181f, 30.027f, -1.552f}, {-6.058f, 29.941f, -1.657f}, {-5.935f, 29.854f, -1.762f},
        {-5.812f, 29.768f, -1.868f}, {-5.688f, 29.694f, -1.981f}, {-5.564f, 29.631f, -2.100f}, {-5.439f, 29.567f,
        -2.219f}, {-5.315f, 29.504f, -2.339f}, {-5.191f, 29.440f, -2.458f}, {-5.066f, 29.377f, -2.577f}, {-4.942f,
        29.313f, -2.696f}, {-4.818f, 29.249f, -2.815f}, {-4.691f, 29.192f, -2.935f}, {-4.561f, 29.143f, -3.055f},
        {-4.430f, 29.092f, -3.173f}, {-4.297f, 29.037f, -3.287f}, {-4.163f, 28.978f, -3.397f}, {-4.027f, 28.915f,
        -3.505f}, {-3.891f, 28.850f, -3.609f}, {-3.754f, 28.783f, -3.711f}, {-3.616f, 28.716f, -3.811f}, {-3.472f,
        28.654f, -3.908f}, {-3.329f, 28.593f, -4.005f}, {-3.184f, 28.534f, -4.102f}, {-3.040f, 28.476f, -4.200f},
        {-2.897f, 28.420f, -4.299f}, {-2.754f, 28.366f, -4.401f}, {-2.611f, 28.314f, -4.504f}, {-2.470f, 28.263f,
        -4.611f}, {-2.332f, 28.214f, -4.720f}, {-2.194f, 28.166f, -4.832f}, {-2.056f, 28.116f, -4.943f}, {-1.919f,
        28.064f, -5.053f}, {-1.781f, 28.009f, -5.161f}, {-1.643f, 27.949f, -5.266f}, {-1.547f, 27.867f, -5.402f},
        {-1.409f, 27.795f, -5.499f}});
    REQUIRE(countStrandsEnteringHead(s, head, headTolerance(head)) == 1);
    for (const HeadDepthRule rule : {HeadDepthRule::Allowance, HeadDepthRule::Rising}) {
        CAPTURE(int(rule));
        StrandSet out = s;
        HeadCollisionParams params;
        params.depthRule = rule;
        resolveHeadCollisions(out, head, {}, params);
        CHECK(countStrandsEnteringHead(out, head, headTolerance(head)) == 0);
        CHECK(maxTurn(out, 0) * 180.0 / M_PI < 45.0);
    }
}

TEST_CASE("resolveHeadCollisions: a strand whose tip alone dips into the head bends out over a length, not at its tip", "[field]")
{
    // A comb stroke or a new strand that ends just inside the head: the contact is at the tip, so
    // a turn there has no edges after it to share it (the comb of HairNet's groom left a strand
    // with a 46-degree turn between its last two edges). Straight strands ending 0.02-0.3 radii
    // inside a unit sphere, met at 10-60 degrees, 16 and 100 vertices.
    const HeadObstacle head = HeadObstacle::sphere(Vec3d(0.0), 1.0);
    for (int n : {16, 100}) {
        StrandSet s;
        for (double depth : {0.02, 0.05, 0.1, 0.2, 0.3}) {
            for (double into : {10.0, 20.0, 35.0, 60.0}) {
                const double a = into * M_PI / 180.0;
                const Vec3d tip(1.0 - depth, 0.0, 0.0);
                // Arriving at the tip from above, at `into` degrees below the tangent plane there.
                const Vec3d dir(-std::sin(a), -std::cos(a), 0.0);
                const Vec3d root = tip - dir * 2.0;
                if (!(root.length() > 1.0)) continue;
                s.addStrand(line(Vec3f(root), Vec3f(dir), 2.f, n));
            }
        }
        const StrandSet before = s;
        REQUIRE(countStrandsEnteringHead(s, head, 0.0) == s.numStrands());
        resolveHeadCollisions(s, head, {});
        HeadObstacle::Probe probe(head);
        double worst = 0.0;
        for (std::size_t i = 0; i < s.numStrands(); ++i) {
            CAPTURE(n, i);
            REQUIRE(s.root(i) == before.root(i));
            for (std::size_t k = 0; k < s.size(i); ++k) REQUIRE(probe.distance(Vec3d(s.positions[s.begin(i) + k])) >= -1e-6);
            worst = std::max(worst, maxTurn(s, i));
        }
        INFO(n << " vertices: largest turn between two segments " << worst * 180.0 / M_PI << " degrees");
        // 100 vertices: 2.9 degrees (13.2 when the smoothing's window was cut at the tip); 16: 12.0.
        CHECK(worst < (n == 100 ? 6.0 : 15.0) * M_PI / 180.0);
    }
}
