#include "TestUtil.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/compare/HairComparison.h>
#include <vdbhair/field/HeadObstacle.h>
#include <vdbhair/io/StrandIO.h>

#include <catch2/catch.hpp>

#include <tbb/global_control.h>

#include <cmath>
#include <filesystem>
#include <random>

using namespace vdbhair;
using Catch::Matchers::Contains;

namespace {

/// @a n straight strands along +y, 1 apart along x, each @a length long in @a vertices vertices.
StrandSet comb(int n, int vertices, float length, Vec3f offset = Vec3f(0.f))
{
    StrandSet s;
    for (int i = 0; i < n; ++i) {
        std::vector<Vec3f> p;
        for (int k = 0; k < vertices; ++k) p.push_back(Vec3f(float(i), length * float(k) / float(vertices - 1), 0.f) + offset);
        s.addStrand(p);
    }
    return s;
}

StrandSet randomHair(std::mt19937& rng, int strands, int vertices)
{
    std::uniform_real_distribution<float> u(-1.f, 1.f);
    StrandSet s;
    for (int i = 0; i < strands; ++i) {
        std::vector<Vec3f> p{Vec3f(u(rng), u(rng), u(rng)) * 3.f};
        for (int k = 1; k < vertices; ++k) p.push_back(p.back() + Vec3f(1.f + 0.3f * u(rng), 0.5f * u(rng), 0.5f * u(rng)) * 0.1f);
        s.addStrand(p);
    }
    return s;
}

} // namespace

TEST_CASE("chamferDistances: each way against brute force, per strand", "[compare]")
{
    std::mt19937 rng(5);
    const StrandSet a = randomHair(rng, 40, 12), b = randomHair(rng, 25, 9);
    const ChamferDistances c = chamferDistances(a, b, true);
    auto brute = [](const StrandSet& from, const StrandSet& to, std::vector<double>* perVertex) {
        double sum = 0.0;
        for (const Vec3f& p : from.positions) {
            double best = 1e300;
            for (const Vec3f& q : to.positions) best = std::min(best, double((p - q).length()));
            sum += best;
            if (perVertex) perVertex->push_back(best);
        }
        return sum / double(from.positions.size());
    };
    std::vector<double> perVertex;
    CHECK(c.aToB == Approx(brute(a, b, &perVertex)).epsilon(1e-6));
    CHECK(c.bToA == Approx(brute(b, a, nullptr)).epsilon(1e-6));
    CHECK(c.mean == Approx(0.5 * (c.aToB + c.bToA)));
    REQUIRE(c.perStrandA.size() == a.numStrands());
    double strand3 = 0.0;
    for (std::size_t k = a.begin(3); k < a.begin(3) + a.size(3); ++k) strand3 += perVertex[k];
    CHECK(c.perStrandA[3] == Approx(strand3 / double(a.size(3))).epsilon(1e-6));
    REQUIRE_THROWS_WITH(chamferDistances(a, StrandSet(), true), Contains("no vertex"));
}

TEST_CASE("compareHairstyles: a hairstyle against itself and against a known shift", "[compare]")
{
    const StrandSet a = comb(10, 33, 8.f);
    CompareParams params;
    params.metersPerUnit = 0.01;  // centimetres: HairGS's 2-4 mm are 0.2-0.4 units
    const HairComparison same = compareHairstyles(a, a, params);
    REQUIRE(same.oriented.size() == 4);
    for (const OrientedMatch& m : same.oriented) {
        CHECK(m.f1 == 1.0);
        CHECK(m.strandConsistency == 1.0);
    }
    CHECK(same.oriented[0].threshold.distance == Approx(0.2));  // 2 mm in centimetres
    CHECK(same.chamfer.mean == 0.0);
    CHECK(same.paired);
    CHECK(same.perm.meanPosition == 0.0);
    CHECK(same.perm.meanCurvature == 0.0);
    CHECK(same.frechetMax == 0.0);
    CHECK(same.leavingVolume == 0.0);

    // Shifted by 0.3 across the strands (0.3 cm = 3 mm): the nearest vertex of each is its own copy,
    // so Chamfer is 0.3 each way; root-aligned errors are 0; Fréchet is 0.3 over the length 8.
    const StrandSet b = comb(10, 33, 8.f, Vec3f(0.f, 0.f, 0.3f));
    const HairComparison shift = compareHairstyles(a, b, params);
    CHECK(shift.chamfer.aToB == Approx(0.3).epsilon(1e-6));
    CHECK(shift.chamfer.bToA == Approx(0.3).epsilon(1e-6));
    CHECK(shift.perm.meanPosition == Approx(0.0).margin(1e-6));
    for (double f : shift.frechet) CHECK(f == Approx(0.3 / 8.0).epsilon(1e-5));
    CHECK(shift.frechetP95 == Approx(0.3 / 8.0).epsilon(1e-5));
    // 2 mm misses everything, 3 mm and 4 mm match everything (the shift is exactly 3 mm: matched at <=).
    CHECK(shift.oriented[0].f1 == 0.0);
    CHECK(shift.oriented[2].f1 == 1.0);

    // Unknown unit: no oriented points unless thresholds are given in file units.
    CompareParams unknown;
    CHECK(compareHairstyles(a, b, unknown).oriented.empty());
    unknown.thresholds = {{0.35, 10.0}};
    const HairComparison fileUnits = compareHairstyles(a, b, unknown);
    REQUIRE(fileUnits.oriented.size() == 1);
    CHECK(fileUnits.oriented[0].f1 == 1.0);

    // Different counts: no strand pairs; the report says so.
    const HairComparison fewer = compareHairstyles(a, comb(7, 33, 8.f), params);
    CHECK_FALSE(fewer.paired);
    CHECK(fewer.frechet.empty());
    CHECK(toJson(fewer)["position_error"].is_null());
    CHECK(toJson(same)["oriented_points"][0]["distance_mm"].get<double>() == Approx(2.0));

    CompareParams bad;
    bad.samples = 2;
    REQUIRE_THROWS_WITH(compareHairstyles(a, a, bad), Contains("samples 2"));
    bad = CompareParams();
    bad.metersPerUnit = -1.0;
    REQUIRE_THROWS_WITH(compareHairstyles(a, a, bad), Contains("unit -1"));
}

TEST_CASE("compareHairstyles: strands passing into a head, and the same report at any thread count", "[compare]")
{
    // A sphere of radius 5 at the origin; A's strands grow outward from its surface; every other
    // strand of B grows from outside it inward, through it.
    StrandSet a;
    for (int i = 0; i < 12; ++i) {
        const double t = 2.0 * M_PI * i / 12.0;
        const Vec3f dir(float(std::cos(t)), 0.f, float(std::sin(t)));
        std::vector<Vec3f> p;
        for (int k = 0; k < 20; ++k) p.push_back(dir * (5.f + 0.25f * float(k)));
        a.addStrand(p);
    }
    StrandSet b = a;
    for (std::size_t i = 0; i < b.numStrands(); i += 2) {
        const Vec3f dir = b.positions[b.begin(i)] * 0.2f;
        for (std::size_t k = 0; k < b.size(i); ++k) b.positions[b.begin(i) + k] = dir * (10.f - 0.5f * float(k));
    }
    const HeadObstacle head = HeadObstacle::sphere(Vec3d(0.0), 5.0);
    const HairComparison c = compareHairstyles(a, b, CompareParams(), &head);
    CHECK(c.headMeasured);
    CHECK(c.enteringHeadA == 0.0);
    CHECK(c.enteringHeadB == Approx(0.5));
    const std::string j2 = toJson(c).dump();
    tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
    CHECK(toJson(compareHairstyles(a, b, CompareParams(), &head)).dump() == j2);
}

TEST_CASE("compareHairstyles: straight.hair against itself (every F1 1, every error 0)", "[compare][data]")
{
    VDBHAIR_REQUIRE_SHARED_DATA();
    const std::string path = test::sharedData() + "/hair/cyhair/straight.hair";
    if (!std::filesystem::exists(path)) {
        WARN("SKIPPED: " << path << " is not available");
        return;
    }
    const StrandSet s = readStrands(path);
    CompareParams params;
    params.metersPerUnit = 0.01;  // Yuksel's files are in centimetres (SOURCES.md)
    const HairComparison c = compareHairstyles(s, s, params);
    REQUIRE(c.oriented.size() == 4);
    for (const OrientedMatch& m : c.oriented) CHECK(m.f1 == 1.0);
    CHECK(c.chamfer.mean == 0.0);
    CHECK(c.perm.meanPosition == 0.0);
    CHECK(c.perm.meanCurvature == 0.0);
    CHECK(c.frechetMax == 0.0);
    CHECK(c.leavingVolume == 0.0);
}
