#include "../TestUtil.h"

#include <vdbhair/strands/Measures.h>

#include <random>

using namespace vdbhair;

TEST_CASE("curvatureProfile / torsionProfile: a helix has curvature r/(r²+c²) and torsion c/(r²+c²)", "[strands]")
{
    // Seeded property test across scales and handedness.
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> radius(0.05, 20.0), pitch(-2.0, 2.0);
    for (int trial = 0; trial < 20; ++trial) {
        const double r = radius(rng), c = pitch(rng) * r;
        // Positions are floats and torsion is a third difference, which amplifies their rounding:
        // sample coarsely enough (and about the origin) that rounding stays below the tolerance.
        const std::size_t n = 201;
        const auto pts = test::helix(r, c, 4.0 * M_PI, n, -2.0 * M_PI);
        std::vector<float> kappa(n), tau(n);
        curvatureProfile(pts.data(), n, kappa.data());
        torsionProfile(pts.data(), n, tau.data());
        const double k0 = r / (r * r + c * c), t0 = c / (r * r + c * c);
        CAPTURE(trial, r, c, k0, t0);
        for (std::size_t i = 2; i + 2 < n; i += 9) {
            CAPTURE(i);
            REQUIRE(kappa[i] == Approx(k0).epsilon(1e-3));
            REQUIRE(tau[i] == Approx(t0).epsilon(1e-2).margin(2e-3 * k0));
        }
    }
}

TEST_CASE("curvatureProfile / torsionProfile: second-order convergence on a helix", "[strands]")
{
    // Halving the step divides the error by about four.
    const double r = 1.5, c = 0.8, k0 = r / (r * r + c * c), t0 = c / (r * r + c * c);
    double errK[2], errT[2];
    for (int level = 0; level < 2; ++level) {
        const std::size_t n = level == 0 ? 41 : 81;
        const auto pts = test::helix(r, c, 2.0 * M_PI, n);
        std::vector<float> kappa(n), tau(n);
        curvatureProfile(pts.data(), n, kappa.data());
        torsionProfile(pts.data(), n, tau.data());
        errK[level] = std::abs(kappa[n / 2] - k0);
        errT[level] = std::abs(tau[n / 2] - t0);
    }
    CAPTURE(errK[0], errK[1], errT[0], errT[1]);
    REQUIRE(errK[0] / errK[1] > 3.5);
    REQUIRE(errT[0] / errT[1] > 3.5);
}

TEST_CASE("curvatureProfile: exact on a circle, even unevenly sampled; torsion 0", "[strands]")
{
    const double r = 3.5;
    std::vector<Vec3f> pts;
    double a = 0.0;
    std::mt19937 rng(1);
    std::uniform_real_distribution<double> step(0.01, 0.3);
    while (a < 5.0) {
        pts.emplace_back(float(r * std::cos(a)), float(r * std::sin(a)), 0.f);
        a += step(rng);
    }
    const std::size_t n = pts.size();
    std::vector<float> kappa(n), tau(n);
    curvatureProfile(pts.data(), n, kappa.data());
    torsionProfile(pts.data(), n, tau.data());
    std::vector<Vec3f> t(n);
    computeTangents(pts.data(), n, t.data());
    for (std::size_t i = 0; i < n; ++i) {
        CAPTURE(i);
        REQUIRE(kappa[i] == Approx(1.0 / r).epsilon(1e-4));
        REQUIRE(tau[i] == Approx(0.0).margin(1e-4));
        // The circle's tangent at angle phi is (-sin phi, cos phi, 0).
        const double phi = std::atan2(pts[i].y(), pts[i].x());
        REQUIRE(t[i].x() == Approx(-std::sin(phi)).margin(1e-4));
        REQUIRE(t[i].y() == Approx(std::cos(phi)).margin(1e-4));
        REQUIRE(t[i].z() == Approx(0.0).margin(1e-6));
    }
}

TEST_CASE("arcLengths / polylineLength: a straight segment and a circle", "[strands]")
{
    const std::vector<Vec3f> line{Vec3f(0.f), Vec3f(1.f, 0.f, 0.f), Vec3f(1.f, 2.f, 0.f), Vec3f(1.f, 2.f, 2.f)};
    std::vector<double> s(line.size());
    arcLengths(line.data(), line.size(), s.data());
    REQUIRE(s == std::vector<double>{0.0, 1.0, 3.0, 5.0});
    REQUIRE(polylineLength(line.data(), line.size()) == 5.0);

    const auto arc = test::circleArc(2.0, M_PI, 10001);
    REQUIRE(polylineLength(arc.data(), arc.size()) == Approx(2.0 * M_PI).epsilon(1e-6));
}

TEST_CASE("computeTangents: repeated points and zero-length strands give no NaN", "[strands]")
{
    const std::vector<Vec3f> rep{Vec3f(0.f), Vec3f(0.f), Vec3f(1.f, 0.f, 0.f), Vec3f(1.f, 0.f, 0.f), Vec3f(2.f, 0.f, 0.f)};
    std::vector<Vec3f> t(rep.size());
    computeTangents(rep.data(), rep.size(), t.data());
    for (const Vec3f& v : t) {
        REQUIRE(v.x() == Approx(1.0));
        REQUIRE(v.y() == 0.f);
    }
    const std::vector<Vec3f> zero(4, Vec3f(1.f, 2.f, 3.f));
    computeTangents(zero.data(), zero.size(), t.data());
    for (std::size_t i = 0; i < zero.size(); ++i) REQUIRE(t[i] == Vec3f(0.f));
    std::vector<float> k(4), tau(4);
    curvatureProfile(zero.data(), 4, k.data());
    torsionProfile(zero.data(), 4, tau.data());
    for (int i = 0; i < 4; ++i) {
        REQUIRE(k[i] == 0.f);
        REQUIRE(tau[i] == 0.f);
    }
}

TEST_CASE("summarizeStrands: counts, ranges and box", "[strands]")
{
    const StrandSet s = test::sampleStrands();
    const StrandSummary sum = summarizeStrands(s);
    REQUIRE(sum.strands == 3);
    REQUIRE(sum.vertices == 17 + 2 + 33);
    REQUIRE(sum.verticesPerStrand.min == 2);
    REQUIRE(sum.verticesPerStrand.max == 33);
    REQUIRE(sum.length.min == Approx(1.0));
    REQUIRE(sum.length.max == Approx(std::sqrt(1.0 + 0.09) * 6.0).epsilon(1e-2));
    REQUIRE(sum.length.mean == Approx((sum.length.min + sum.length.max + polylineLength(s.data(2), s.size(2))) / 3.0));
}
