#include <vdbhair/Exceptions.h>
#include <vdbhair/strands/StrandStats.h>

#include "TestUtil.h"

#include <catch2/catch.hpp>

#include <cmath>

using namespace vdbhair;
using Catch::Matchers::Contains;

TEST_CASE("totalTurning: a straight strand turns 0, an arc of n points over theta turns theta (n-2)/(n-1)", "[strands]")
{
    const std::vector<Vec3f> line{Vec3f(0.f), Vec3f(1.f, 0.f, 0.f), Vec3f(2.f, 0.f, 0.f), Vec3f(2.f, 0.f, 0.f), Vec3f(3.f, 0.f, 0.f)};
    CHECK(totalTurning(line.data(), line.size()) == 0.0);
    for (double r : {0.01, 1.0, 100.0}) {
        const double theta = 2.5;
        const int n = 41;
        std::vector<Vec3f> arc;
        for (int k = 0; k < n; ++k) {
            const double a = theta * k / (n - 1);
            arc.emplace_back(float(r * std::cos(a)), float(r * std::sin(a)), 0.f);
        }
        CAPTURE(r);
        // A polygon inscribed in the arc turns by theta/(n-1) at each of its n-2 inner vertices.
        CHECK(totalTurning(arc.data(), arc.size()) == Approx(theta * (n - 2) / (n - 1)).margin(1e-5));
    }
}

TEST_CASE("computeStrandStatistics: histograms of known lengths, turning and curvature", "[strands]")
{
    StrandSet s;
    // Ten straight strands of lengths 1..10 (2 vertices each): one a bin.
    for (int k = 1; k <= 10; ++k) s.addStrand(std::vector<Vec3f>{Vec3f(0.f, 0.f, float(k)), Vec3f(float(k), 0.f, float(k))});
    // One half circle of radius 2 (33 vertices): curvature 1/2 at every vertex.
    std::vector<Vec3f> arc;
    for (int k = 0; k <= 32; ++k) arc.emplace_back(2.f * std::cos(3.14159265f * k / 32.f), 2.f * std::sin(3.14159265f * k / 32.f), 50.f);
    s.addStrand(arc);
    const StrandStatistics st = computeStrandStatistics(s, 10);
    CHECK(st.length.total() == 11);
    CHECK(st.verticesPerStrand.total() == 11);
    CHECK(st.verticesPerStrand.counts.front() == 10);
    CHECK(st.verticesPerStrand.counts.back() == 1);
    CHECK(st.curvatureHist.total() == s.numVertices());
    CHECK(st.curvature.max == Approx(0.5).epsilon(1e-4));
    CHECK(st.turning.max == Approx(180.0 * 31.0 / 32.0).epsilon(1e-4));
    CHECK(st.turning.min == 0.0);
    // The straight strands alone: lengths 1..10 fall one a bin.
    StrandSet straight;
    for (int k = 1; k <= 10; ++k) straight.addStrand(std::vector<Vec3f>{Vec3f(0.f), Vec3f(float(k), 0.f, 0.f)});
    const StrandStatistics ls = computeStrandStatistics(straight, 10);
    CHECK(ls.length.lo == 1.0);
    CHECK(ls.length.hi == 10.0);
    for (std::size_t b = 0; b < 10; ++b) {
        CAPTURE(b);
        CHECK(ls.length.counts[b] == 1);
    }
    REQUIRE_THROWS_WITH(computeStrandStatistics(s, 0), Contains("bins 0: must be between 1 and 10000"));
}
