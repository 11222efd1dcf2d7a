#include "SynthTestUtil.h"

#include <vdbhair/synth/Clustering.h>
#include <vdbhair/synth/Pca.h>

#include <catch2/catch.hpp>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>

#include <queue>
#include <set>

using namespace vdbhair;

namespace {
const ScalpMap& unitMap()
{
    static const ScalpMap map{ScalpSphere{}};
    return map;
}

/// Every cluster is one connected component of the root graph restricted to its members.
bool clustersConnected(const StrandSamples& s, const std::vector<std::uint32_t>& label, int k)
{
    const auto graph = neighbourGraph(s.roots, k);
    std::vector<std::uint8_t> seen(label.size(), 0);
    std::set<std::uint32_t> started;
    for (std::uint32_t i = 0; i < label.size(); ++i) {
        if (seen[i]) continue;
        if (!started.insert(label[i]).second) return false;  // a second component of the same cluster
        std::queue<std::uint32_t> q;
        q.push(i);
        seen[i] = 1;
        while (!q.empty()) {
            const std::uint32_t a = q.front();
            q.pop();
            for (const std::uint32_t* it = graph.begin(a); it != graph.end(a); ++it)
                if (const std::uint32_t b = *it; !seen[b] && label[b] == label[a]) {
                    seen[b] = 1;
                    q.push(b);
                }
        }
    }
    return true;
}
} // namespace

TEST_CASE("sampleStrands: rows are root-relative in the root frame, in radius units", "[synth]")
{
    ScalpSphere sphere;
    sphere.radius = 2.0;
    const ScalpMap map(sphere);
    StrandSet s;
    // A strand straight up from the top of the sphere of radius 2, 1 long: local (0, l/(n-1) * 0.5, 0).
    s.addStrand({Vec3f(0, 2, 0), Vec3f(0, 2.4f, 0), Vec3f(0, 3, 0)});
    const StrandSamples samples = sampleStrands(s, map, 5);
    REQUIRE(samples.count() == 1);
    CHECK(samples.lengths[0] == Approx(1.0));
    for (int l = 0; l < 5; ++l) {
        CHECK(samples.row(0)[3 * l] == Approx(0.0).margin(1e-6));
        CHECK(samples.row(0)[3 * l + 1] == Approx(0.125 * l).margin(1e-6));
        CHECK(samples.row(0)[3 * l + 2] == Approx(0.0).margin(1e-6));
    }
    const StrandSet back = samplesToStrands(samples, map.radius());
    CHECK((back.tip(0) - Vec3f(0, 3, 0)).length() < 1e-5f);
    StrandSet bad;
    bad.addStrand({Vec3f(0, 2, 0)});
    CHECK_THROWS_WITH(sampleStrands(bad, map, 5), Catch::Contains("strand 0 has 1 vertex"));
    CHECK_THROWS_WITH(sampleStrands(s, map, 1), Catch::Contains("1 vertices per strand"));
}

TEST_CASE("sampleStrands: an order picks the strand each row takes", "[synth]")
{
    const ScalpMap& map = unitMap();
    StrandSet s;
    for (int i = 0; i < 5; ++i) {
        const float a = 0.3f * float(i);
        const Vec3f root(std::sin(a), std::cos(a), 0.f);
        s.addStrand({root, root * 1.2f + Vec3f(0.f, 0.f, 0.1f * float(i)), root * 1.5f});
    }
    const StrandSamples all = sampleStrands(s, map, 4);
    const std::vector<std::uint32_t> order{3, 0, 4, 4, 1};
    const StrandSamples picked = sampleStrands(s, map, 4, true, &order);
    REQUIRE(picked.count() == order.size());
    for (std::size_t i = 0; i < order.size(); ++i) {
        CHECK(picked.roots[i] == all.roots[order[i]]);
        CHECK(picked.lengths[i] == all.lengths[order[i]]);
        for (std::size_t k = 0; k < picked.dim(); ++k) CHECK(picked.row(i)[k] == all.row(order[i])[k]);
    }
    const std::vector<std::uint32_t> bad{0, 5};
    CHECK_THROWS_WITH(sampleStrands(s, map, 4, true, &bad), Catch::Contains("order names strand 5 of 5"));
}

TEST_CASE("neighbourGraph: the symmetric k-nearest-neighbour graph, sorted rows, any thread count", "[synth]")
{
    // Seeded points in a box; the graph against a brute-force one.
    std::vector<Vec3d> pts;
    std::uint64_t x = 12345;
    const auto next = [&] { x = x * 6364136223846793005ull + 1442695040888963407ull; return double(x >> 11) / double(1ull << 53); };
    for (int i = 0; i < 3000; ++i) pts.emplace_back(next(), next(), 0.2 * next());
    const int k = 6;
    std::vector<std::set<std::uint32_t>> expect(pts.size());
    for (std::uint32_t i = 0; i < pts.size(); ++i) {
        std::vector<std::pair<double, std::uint32_t>> d;
        for (std::uint32_t j = 0; j < pts.size(); ++j) d.emplace_back((pts[i] - pts[j]).lengthSqr(), j);
        std::partial_sort(d.begin(), d.begin() + k + 1, d.end());
        for (int m = 0; m <= k; ++m) {
            if (d[std::size_t(m)].second == i) continue;
            expect[i].insert(d[std::size_t(m)].second);
            expect[d[std::size_t(m)].second].insert(i);
        }
    }
    const NeighbourGraph g = neighbourGraph(pts, k);
    REQUIRE(g.offsets.size() == pts.size() + 1);
    std::size_t mismatched = 0;
    for (std::uint32_t i = 0; i < pts.size(); ++i) {
        const std::vector<std::uint32_t> row(g.begin(i), g.end(i));
        if (row != std::vector<std::uint32_t>(expect[i].begin(), expect[i].end())) ++mismatched;  // sorted, unique, symmetric
    }
    CHECK(mismatched == 0);
    tbb::task_arena one(1);
    NeighbourGraph serial;
    one.execute([&] { serial = neighbourGraph(pts, k); });
    CHECK(serial.offsets == g.offsets);
    CHECK(serial.indices == g.indices);
    CHECK(neighbourGraph({Vec3d(0.0)}, k).indices.empty());
}

TEST_CASE("fitPca: rows spanning a plane have two components", "[synth]")
{
    const std::size_t n = 200, dim = 12;
    std::vector<float> rows(n * dim), a(dim), b(dim), m(dim);
    for (std::size_t i = 0; i < dim; ++i) {
        a[i] = float(std::sin(0.7 * i));
        b[i] = float(std::cos(1.3 * i + 0.2));
        m[i] = float(0.1 * i);
    }
    for (std::size_t r = 0; r < n; ++r) {
        const float x = float(std::sin(0.37 * r)) * 3.0f, y = float(std::cos(0.11 * r * r));
        for (std::size_t i = 0; i < dim; ++i) rows[r * dim + i] = m[i] + x * a[i] + y * b[i];
    }
    const Pca pca = fitPca(rows.data(), n, dim, 5);
    REQUIRE(pca.components == 5);
    CHECK(pca.variance[0] > 0.1);
    CHECK(pca.variance[1] > 0.01);
    CHECK(pca.variance[2] < 1e-9 * pca.variance[0]);
    CHECK(pca.variance[0] + pca.variance[1] == Approx(pca.totalVariance).epsilon(1e-9));
    // Two coordinates reconstruct every row.
    std::vector<float> f(5), back(dim);
    for (std::size_t r = 0; r < n; r += 17) {
        pca.project(rows.data() + r * dim, f.data());
        CHECK(std::abs(f[2]) < 1e-4f);
        pca.reconstruct(f.data(), back.data());
        for (std::size_t i = 0; i < dim; ++i) CHECK(back[i] == Approx(rows[r * dim + i]).margin(1e-4));
    }
    CHECK_THROWS_WITH(fitPca(rows.data(), 0, dim, 5), Catch::Contains("at least one row"));
}

TEST_CASE("clusterSamples: strands made as k wisps are recovered as connected clusters", "[synth]")
{
    std::vector<int> truth;
    const int wisps = 6;
    const StrandSet hair = test::wispHairstyle(1200, wisps, &truth);
    const StrandSamples samples = sampleStrands(hair, unitMap(), 32);
    ClusterParams params;
    for (std::uint64_t seed : {1u, 2u, 3u}) {
        params.seed = seed;
        const Clustering c = clusterSamples(samples, unitMap(), wisps, false, params);
        REQUIRE(c.label.size() == samples.count());
        CAPTURE(seed, c.energy, c.clusters);
        // Islands would add clusters; the graph is connected here.
        CHECK(c.seededIslands == 0);
        CHECK(c.centers.count() == std::size_t(wisps));
        const std::vector<int> got(c.label.begin(), c.label.end());
        CHECK(test::adjustedRandIndex(truth, got) > 0.9);
        CHECK(clustersConnected(samples, c.label, params.neighbours));
        // The energy ends at the true wisps' own (members about their means) or below.
        {
            std::vector<double> mean(std::size_t(wisps) * samples.dim(), 0.0);
            std::vector<int> n(std::size_t(wisps), 0);
            for (std::size_t s = 0; s < samples.count(); ++s) {
                for (std::size_t i = 0; i < samples.dim(); ++i) mean[std::size_t(truth[s]) * samples.dim() + i] += samples.row(s)[i];
                ++n[std::size_t(truth[s])];
            }
            double truthEnergy = 0.0;
            for (std::size_t s = 0; s < samples.count(); ++s)
                for (std::size_t i = 0; i < samples.dim(); ++i) {
                    const double d = samples.row(s)[i] - mean[std::size_t(truth[s]) * samples.dim() + i] / n[std::size_t(truth[s])];
                    truthEnergy += d * d;
                }
            CAPTURE(truthEnergy);
            CHECK(c.energy.back() <= c.energy.front());
            CHECK(c.energy.back() <= 1.01 * truthEnergy);
        }
        // Centres are the members' means: a centre's tip is the mean of its members' tips.
        std::vector<double> sum(std::size_t(wisps), 0.0);
        std::vector<int> count(std::size_t(wisps), 0);
        const std::size_t tip = samples.dim() - 2;  // y of the last vertex
        for (std::size_t s = 0; s < samples.count(); ++s) {
            sum[c.label[s]] += samples.row(s)[tip];
            ++count[c.label[s]];
        }
        for (int k = 0; k < wisps; ++k) CHECK(c.centers.row(std::size_t(k))[tip] == Approx(sum[std::size_t(k)] / count[std::size_t(k)]).epsilon(1e-5));
    }
    // The same seed gives the same clustering.
    params.seed = 5;
    const Clustering a = clusterSamples(samples, unitMap(), wisps, false, params);
    const Clustering b = clusterSamples(samples, unitMap(), wisps, false, params);
    CHECK(a.label == b.label);
    CHECK(a.energy == b.energy);
}

TEST_CASE("clusterSamples: adaptive clustering splits until every strand is within the threshold", "[synth]")
{
    std::vector<int> truth;
    const StrandSet hair = test::wispHairstyle(800, 5, &truth);
    const StrandSamples samples = sampleStrands(hair, unitMap(), 32);
    ClusterParams params;
    params.threshold = 0.02;  // above the noise within a wisp, far below the distance between wisps
    params.maxSplitRounds = 20;
    // From 2 clusters, splitting finds the 5 wisps and stops there.
    const Clustering c = clusterSamples(samples, unitMap(), 2, true, params);
    CAPTURE(c.clusters, c.largestDistance);
    CHECK(c.centers.count() == 5);
    CHECK(c.largestDistance <= params.threshold);
    CHECK(c.clusters.back() > c.clusters.front());
    CHECK(c.energy.back() < 0.01 * c.energy.front());
    CHECK(test::adjustedRandIndex(truth, std::vector<int>(c.label.begin(), c.label.end())) > 0.95);
    // A threshold below the noise keeps splitting, up to the cap on clusters (a share of the strands).
    params.threshold = 1e-6;
    params.maxSplitRounds = 100;
    const Clustering d = clusterSamples(samples, unitMap(), 2, true, params);
    CHECK(d.centers.count() == std::size_t(800 * params.maxClusterFraction));
    params.threshold = -1.0;
    CHECK_THROWS_WITH(clusterSamples(samples, unitMap(), 2, true, params), Catch::Contains("threshold -1: must be a positive finite"));
}

TEST_CASE("buildHierarchy: each level has about a quarter of the clusters of the one below", "[synth]")
{
    const StrandSet hair = test::wispHairstyle(1600, 8);
    const StrandSamples samples = sampleStrands(hair, unitMap(), 24);
    ClusterParams params;
    params.initialClusters = 100;
    const ClusterHierarchy h = buildHierarchy(samples, unitMap(), params);
    REQUIRE(h.levels.size() == 3);
    REQUIRE(h.clusterings.size() == 2);
    CHECK(h.levels[0].count() == 1600);
    CHECK(h.levels[1].count() >= 100);
    CHECK(h.levels[2].count() == h.levels[1].count() / 4);
    for (std::size_t l = 0; l < 2; ++l) {
        CHECK(h.clusterings[l].label.size() == h.levels[l].count());
        CHECK(clustersConnected(h.levels[l], h.clusterings[l].label, params.neighbours));
    }
    // Centre roots lie on the scalp.
    for (const Vec3d& r : h.levels[2].roots) CHECK(r.length() == Approx(1.0).margin(1e-9));
    StrandSamples few = samples;
    few.local.resize(10 * few.dim());
    few.roots.resize(10);
    few.scalp.resize(10);
    few.frames.resize(10);
    few.lengths.resize(10);
    CHECK_THROWS_WITH(buildHierarchy(few, unitMap(), params), Catch::Contains("10 strands for 3 levels"));
}
