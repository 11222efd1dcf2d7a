#include <vdbhair/dataset/RootSubsample.h>

#include <catch2/catch.hpp>

#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <random>

using namespace vdbhair;

namespace {

/// @a n two-vertex strands rooted uniformly at random in the unit square (z = 0), growing up.
StrandSet randomRoots(std::size_t n, unsigned seed)
{
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0.f, 1.f);
    StrandSet s;
    for (std::size_t i = 0; i < n; ++i) {
        const Vec3f r(u(rng), u(rng), 0.f);
        s.addStrand(std::vector<Vec3f>{r, r + Vec3f(0.f, 0.f, 0.1f)});
    }
    return s;
}

} // namespace

TEST_CASE("selectEvenRoots: N strands whose roots are at least the covering bound apart", "[dataset]")
{
    const StrandSet s = randomRoots(10000, 3);
    for (std::size_t count : {10, 100, 400}) {
        const RootSelection sel = selectEvenRoots(s, count);
        CAPTURE(count, sel.minSpacing, sel.coverageRadius);
        REQUIRE(sel.strands.size() == count);
        CHECK(std::is_sorted(sel.strands.begin(), sel.strands.end()));
        CHECK(std::adjacent_find(sel.strands.begin(), sel.strands.end()) == sel.strands.end());
        // Farthest-point sampling: no two taken roots closer than the radius that covers every root.
        CHECK(sel.minSpacing >= sel.coverageRadius);
        // count disks of that radius cover the unit square (its 10,000 samples), so
        // count * pi * r^2 >= about 1: the spacing is at least 1 / sqrt(pi count), less a margin for the sampling.
        CHECK(sel.minSpacing >= 0.9 / std::sqrt(3.14159265 * double(count)));
    }
}

TEST_CASE("selectEvenRoots: every strand when asked for as many or more; none for 0", "[dataset]")
{
    const StrandSet s = randomRoots(20, 1);
    CHECK(selectEvenRoots(s, 20).strands.size() == 20);
    CHECK(selectEvenRoots(s, 1000).strands.size() == 20);
    CHECK(selectEvenRoots(s, 1000).coverageRadius == 0.0);
    CHECK(selectEvenRoots(s, 0).strands.empty());
    CHECK(selectEvenRoots(StrandSet{}, 5).strands.empty());
}

TEST_CASE("subsampleStrands: identical for 1 and 2 threads, attributes kept", "[dataset]")
{
    StrandSet s = randomRoots(5000, 11);
    for (std::size_t v = 0; v < s.numVertices(); ++v) s.thickness.push_back(float(v));
    StrandSet r[2];
    for (int threads : {1, 2}) {
        tbb::global_control c(tbb::global_control::max_allowed_parallelism, std::size_t(threads));
        r[threads - 1] = subsampleStrands(s, 333);
    }
    REQUIRE(r[0].numStrands() == 333);
    CHECK(r[0].positions == r[1].positions);
    REQUIRE(r[0].thickness.size() == r[0].numVertices());
    // A kept strand keeps its own thickness: vertex v of the input had thickness v.
    const std::size_t i = std::size_t(r[0].thickness[0]) / 2;
    CHECK(s.root(i) == r[0].root(0));
}
