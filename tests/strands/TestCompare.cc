#include <vdbhair/Exceptions.h>
#include <vdbhair/field/HairVolume.h>
#include <vdbhair/strands/Compare.h>

#include <catch2/catch.hpp>

#include <tbb/global_control.h>

#include <cmath>
#include <map>
#include <random>
#include <set>

using namespace vdbhair;
using Catch::Matchers::Contains;

namespace {

StrandSet randomHair(std::mt19937& rng, int strands, int vertices, float extent)
{
    std::uniform_real_distribution<float> u(-1.f, 1.f);
    StrandSet s;
    for (int i = 0; i < strands; ++i) {
        std::vector<Vec3f> p{Vec3f(u(rng), u(rng), u(rng)) * extent};
        for (int k = 1; k < vertices; ++k) p.push_back(p.back() + Vec3f(1.f + 0.3f * u(rng), 0.5f * u(rng), 0.5f * u(rng)) * 0.1f);
        s.addStrand(p);
    }
    return s;
}

/// HairGS's definition, point by point against every point (the oracle).
void bruteForce(const StrandSet& from, const StrandSet& to, const OrientedThreshold& t, double& share, double& consistency)
{
    const double c = std::cos(t.angleDegrees * M_PI / 180.0);
    std::size_t matched = 0, points = 0, strands = 0;
    double sum = 0.0;
    for (std::size_t i = 0; i < from.numStrands(); ++i) {
        std::map<std::size_t, std::size_t> perStrand;
        std::size_t n = 0;
        for (std::size_t k = 0; k + 1 < from.size(i); ++k, ++n) {
            const Vec3f a = from.positions[from.begin(i) + k], da = (from.positions[from.begin(i) + k + 1] - a).unitSafe();
            std::set<std::size_t> hits;
            for (std::size_t j = 0; j < to.numStrands(); ++j) {
                for (std::size_t m = 0; m + 1 < to.size(j); ++m) {
                    const Vec3f b = to.positions[to.begin(j) + m], db = (to.positions[to.begin(j) + m + 1] - b).unitSafe();
                    if (double((a - b).lengthSqr()) <= t.distance * t.distance && double(da.dot(db)) >= c) hits.insert(j);
                }
            }
            if (!hits.empty()) ++matched;
            for (std::size_t j : hits) ++perStrand[j];
        }
        std::size_t best = 0;
        for (const auto& e : perStrand) best = std::max(best, e.second);
        if (n) {
            sum += double(best) / double(n);
            ++strands;
        }
        points += n;
    }
    share = double(matched) / double(points);
    consistency = sum / double(strands);
}

/// @a m (matchOrientedPoints(@a predicted, @a reference, @a th)) against the brute force, threshold
/// by threshold; F1 too with @a withF1.
void checkAgainstBruteForce(const StrandSet& predicted, const StrandSet& reference, const std::vector<OrientedThreshold>& th,
                            const std::vector<OrientedMatch>& m, bool withF1)
{
    for (std::size_t t = 0; t < th.size(); ++t) {
        CAPTURE(t);
        double precision, recall, consistency, unused;
        bruteForce(predicted, reference, th[t], precision, unused);
        bruteForce(reference, predicted, th[t], recall, consistency);
        CHECK(m[t].precision == Approx(precision).margin(1e-12));
        CHECK(m[t].recall == Approx(recall).margin(1e-12));
        CHECK(m[t].strandConsistency == Approx(consistency).margin(1e-12));
        if (!withF1) continue;
        const double f1 = precision + recall > 0.0 ? 2.0 * precision * recall / (precision + recall) : 0.0;
        CHECK(m[t].f1 == Approx(f1).margin(1e-12));
    }
}

} // namespace

TEST_CASE("matchOrientedPoints: HairGS's precision, recall, F1 and strand consistency, against brute force", "[strands]")
{
    std::mt19937 rng(5);
    for (int round = 0; round < 4; ++round) {
        const StrandSet a = randomHair(rng, 40, 12, 0.6f), b = randomHair(rng, 50, 10, 0.6f);
        const std::vector<OrientedThreshold> th{{0.05, 20.0}, {0.1, 30.0}, {0.15, 90.0}, {0.2, 180.0}};
        const std::vector<OrientedMatch> m = matchOrientedPoints(a, b, th);
        REQUIRE(m.size() == th.size());
        CAPTURE(round);
        checkAgainstBruteForce(a, b, th, m, /*withF1=*/true);
        CHECK(m[3].precision > 0.0);
    }
}

TEST_CASE("matchOrientedPoints: near copies (the likely strand, the listing and the counting), against brute force", "[strands]")
{
    // Dense, nearly parallel strands and a copy jittered by about a threshold, strands in another
    // order, some reversed and some cut short: strands compete for each other's points, so the
    // exact consistency needs the listing and the bounds, not only the likely strand.
    std::mt19937 rng(23);
    std::uniform_real_distribution<float> u(-1.f, 1.f);
    StrandSet a;
    for (int i = 0; i < 60; ++i) {
        std::vector<Vec3f> p{Vec3f(0.02f * float(i % 10), 0.02f * float(i / 10), 0.f)};
        for (int k = 1; k < 14; ++k) p.push_back(p.back() + Vec3f(0.01f * u(rng), 0.01f * u(rng), 0.05f));
        a.addStrand(p);
    }
    for (const float jitter : {0.0f, 0.004f, 0.015f}) {
        StrandSet b;
        for (std::size_t n = 0; n < a.numStrands(); ++n) {
            const std::size_t i = (n * 37) % a.numStrands();
            std::vector<Vec3f> p(a.positions.begin() + std::ptrdiff_t(a.begin(i)), a.positions.begin() + std::ptrdiff_t(a.end(i)));
            for (Vec3f& x : p) x += Vec3f(u(rng), u(rng), u(rng)) * jitter;
            if (n % 9 == 0) std::reverse(p.begin(), p.end());
            if (n % 7 == 0) p.resize(6);
            b.addStrand(p);
        }
        const std::vector<OrientedThreshold> th{{0.01, 20.0}, {0.02, 30.0}, {0.03, 90.0}};
        for (const bool threaded : {false, true}) {
            const std::vector<OrientedMatch> m = matchOrientedPoints(b, a, th, false, threaded);
            CAPTURE(jitter, threaded);
            checkAgainstBruteForce(b, a, th, m, /*withF1=*/false);
        }
    }
}

TEST_CASE("matchOrientedPoints: a hairstyle against itself, and reversed", "[strands]")
{
    std::mt19937 rng(9);
    const StrandSet a = randomHair(rng, 30, 8, 5.0f);  // strands far apart
    const std::vector<OrientedMatch> same = matchOrientedPoints(a, a, {{1e-6, 0.5}, {0.01, 20.0}});
    for (const OrientedMatch& m : same) {
        CHECK(m.precision == 1.0);
        CHECK(m.recall == 1.0);
        CHECK(m.f1 == 1.0);
        CHECK(m.strandConsistency == 1.0);
    }
    // Tip first: the same points a segment on, opposite directions.
    StrandSet reversed;
    for (std::size_t i = 0; i < a.numStrands(); ++i) {
        std::vector<Vec3f> p(a.positions.begin() + std::ptrdiff_t(a.begin(i)), a.positions.begin() + std::ptrdiff_t(a.begin(i) + a.size(i)));
        std::reverse(p.begin(), p.end());
        reversed.addStrand(p);
    }
    const double step = 0.2;  // longer than any segment
    CHECK(matchOrientedPoints(reversed, a, {{step, 20.0}})[0].f1 == 0.0);
    CHECK(matchOrientedPoints(reversed, a, {{step, 20.0}}, /*bidirectional=*/true)[0].f1 == 1.0);
    REQUIRE_THROWS_WITH(matchOrientedPoints(a, a, {{-1.0, 20.0}}), Contains("distance -1"));
    REQUIRE_THROWS_WITH(matchOrientedPoints(a, a, {{1.0, 200.0}}), Contains("angle 200"));
    REQUIRE_THROWS_WITH(matchOrientedPoints(StrandSet(), a, {{1.0, 20.0}}), Contains("predicted hair has no segment"));
}

TEST_CASE("matchOrientedPoints and strandPairErrors: identical for 1 and 2 threads", "[strands]")
{
    std::mt19937 rng(2);
    const StrandSet a = randomHair(rng, 3000, 16, 1.0f), b = randomHair(rng, 3000, 16, 1.0f);
    std::vector<OrientedMatch> m[2];
    StrandPairErrors e[2];
    for (int t = 0; t < 2; ++t) {
        tbb::global_control c(tbb::global_control::max_allowed_parallelism, std::size_t(t + 1));
        m[t] = matchOrientedPoints(a, b, {{0.05, 30.0}});
        e[t] = strandPairErrors(a, b);
    }
    CHECK(m[0][0].precision == m[1][0].precision);
    CHECK(m[0][0].strandConsistency == m[1][0].strandConsistency);
    CHECK(e[0].meanPosition == e[1].meanPosition);
    CHECK(e[0].meanCurvature == e[1].meanCurvature);
}

TEST_CASE("strandPairErrors: Perm's root-aligned position and three-point curvature errors on circles", "[strands]")
{
    // Half circles of radius 1 and 2, as many vertices; and the first moved: root-aligned, no error.
    auto arc = [](double r, const Vec3f& origin) {
        std::vector<Vec3f> p;
        for (int k = 0; k <= 400; ++k) {
            const double t = M_PI * k / 400.0;
            p.push_back(origin + Vec3f(float(r * std::cos(t)), float(r * std::sin(t)), 0.f));
        }
        return p;
    };
    StrandSet a, moved, bigger;
    a.addStrand(arc(1.0, Vec3f(0.f)));
    moved.addStrand(arc(1.0, Vec3f(3.f, -2.f, 5.f)));
    bigger.addStrand(arc(2.0, Vec3f(0.f)));
    const StrandPairErrors same = strandPairErrors(a, moved);
    CHECK(same.meanPosition == Approx(0.0).margin(1e-5));
    CHECK(same.meanCurvature == Approx(0.0).margin(1e-3));
    // Curvature 1 against 1/2 everywhere.
    CHECK(strandPairErrors(a, bigger).meanCurvature == Approx(0.5).epsilon(1e-3));
    REQUIRE_THROWS_WITH(strandPairErrors(a, StrandSet()), Contains("1 strands against 0"));
    REQUIRE_THROWS_WITH(strandPairErrors(a, a, 2), Contains("at least 3"));
}

TEST_CASE("a strand leaves a reference's hair volume when a point is more than a voxel outside its voxels", "[compare]")
{
    // The reference: a straight strand along x from 0 to 10 with two vertices (its segment is
    // sampled at half a voxel); voxel 0.5, so the volume is |y|, |z| <= 0.75 around it.
    StrandSet ref;
    ref.addStrand({Vec3f(0.f), Vec3f(10.f, 0.f, 0.f)});
    StrandSet s;
    s.addStrand({Vec3f(1.f, 0.f, 0.f), Vec3f(9.f, 0.f, 0.f)});         // along it: in
    s.addStrand({Vec3f(1.f, 0.5f, 0.f), Vec3f(9.f, 0.5f, 0.f)});       // one voxel off: in (dilated)
    s.addStrand({Vec3f(1.f, 0.f, 0.f), Vec3f(5.f, 0.f, 0.f), Vec3f(6.f, 1.6f, 0.f)});  // its tip three voxels off: out
    s.addStrand({Vec3f(1.f, 0.f, 0.f), Vec3f(12.f, 0.f, 0.f)});        // past the reference's end by 4 voxels: out
    CHECK(countStrandsLeavingVolume(s, ref, 0.5) == 2);
    CHECK(countStrandsLeavingVolume(s, ref, 0.5, false) == 2);
    CHECK(countStrandsLeavingVolume(ref, ref, 0.5) == 0);
    CHECK(countStrandsLeavingVolume(s, ref, 2.0) == 0);  // coarse voxels hold all of it
    REQUIRE_THROWS_WITH(countStrandsLeavingVolume(s, ref, 0.0), Catch::Matchers::Contains("must be a positive length"));
    REQUIRE_THROWS_WITH(countStrandsLeavingVolume(s, ref, 1e-6), Catch::Matchers::Contains("give a larger voxel"));
}
