#include "SynthTestUtil.h"

#include <vdbhair/scalp/Follicles.h>
#include <vdbhair/synth/FeatureMap.h>
#include <vdbhair/synth/RootScatter.h>

#include <catch2/catch.hpp>

using namespace vdbhair;

namespace {
const ScalpMap& unitMap()
{
    static const ScalpMap map{ScalpSphere{}};
    return map;
}

std::vector<Vec3d> capCoords(std::size_t n)
{
    const StrandSet hair = test::wispHairstyle(n, 1, nullptr, 2);
    std::vector<Vec3d> out;
    for (std::size_t s = 0; s < hair.numStrands(); ++s) out.push_back(unitMap().toScalp(Vec3d(hair.root(s))));
    return out;
}

/// An example four times as dense on one side of a cap (u below @c split) as on the other: its
/// roots @c coords, the grid and the mask of the whole cap.
struct DenseSparseExample
{
    std::vector<Vec3d> coords;
    double split = 0.0;
    UvGrid grid;
    FeatureImage mask;
};

DenseSparseExample denseSparseExample()
{
    DenseSparseExample e;
    const std::vector<Vec3d> all = capCoords(4000);
    std::vector<double> us;
    for (const Vec3d& c : all) us.push_back(c.x());
    std::nth_element(us.begin(), us.begin() + std::ptrdiff_t(us.size() / 2), us.end());
    e.split = us[us.size() / 2];
    for (std::size_t i = 0; i < all.size(); ++i)
        if (all[i].x() < e.split || i % 4 == 0) e.coords.push_back(all[i]);
    e.grid = uvGridAround(all, 0.02);
    std::vector<float> f(all.size(), 0.0f);
    e.mask = buildFeatureMap(e.grid, all, f.data(), 1, all, 2.0 * medianUvSpacing(all));
    return e;
}

/// The roots' spacing on either side of @a split, 0.2 away from it: the dense side's, the sparse side's.
std::pair<FollicleStats, FollicleStats> sideSpacings(const ScatteredRoots& roots, double split)
{
    std::vector<Vec3f> left, right;
    for (std::size_t i = 0; i < roots.scalp.size(); ++i) {
        const double u = roots.scalp[i].x();
        if (u < split - 0.2) left.emplace_back(roots.positions[i]);
        if (u > split + 0.2) right.emplace_back(roots.positions[i]);
    }
    return {measureFollicles(left), measureFollicles(right)};
}
} // namespace

TEST_CASE("buildFeatureMap: a linear feature is interpolated exactly at roots and between them within bounds", "[synth]")
{
    const std::vector<Vec3d> coords = capCoords(400);
    std::vector<float> f;
    for (const Vec3d& c : coords) f.insert(f.end(), {float(c.x()), float(2 * c.y())});
    const UvGrid grid = uvGridAround(coords, 0.02);
    const double radius = 2.0 * medianUvSpacing(coords);
    const FeatureImage map = buildFeatureMap(grid, coords, f.data(), 2, coords, radius);
    REQUIRE(map.width == grid.width);
    std::size_t valid = 0;
    for (int y = 0; y < map.height; ++y)
        for (int x = 0; x < map.width; ++x) {
            if (!map.isValid(x, y)) continue;
            ++valid;
            // Shepard weights reproduce a linear function up to the spread of the four neighbours.
            CHECK(map.pixel(x, y)[0] == Approx(grid.u(x)).margin(2 * radius));
            CHECK(map.pixel(x, y)[1] == Approx(2 * grid.v(y)).margin(4 * radius));
        }
    CHECK(valid > map.pixelCount() / 4);
    CHECK(valid < map.pixelCount());  // the corners of the box around a cap are not hair
    // nearestFeature from an invalid corner returns a valid pixel's value.
    float out[2];
    REQUIRE(nearestFeature(map, grid, grid.u(0), grid.v(0), out));
    CHECK(out[0] > float(grid.u(0)));
}

TEST_CASE("scatterRoots: roots on the scalp, in the region, more even after relaxation, deterministic", "[synth]")
{
    const std::vector<Vec3d> coords = capCoords(2000);
    const UvGrid grid = uvGridAround(coords, 0.02);
    std::vector<float> f(coords.size(), 0.0f);
    const FeatureImage mask = buildFeatureMap(grid, coords, f.data(), 1, coords, 2.0 * medianUvSpacing(coords));
    RootScatterParams params;
    params.count = 1500;
    params.seed = 3;
    const ScatteredRoots relaxed = scatterRoots(unitMap(), grid, mask, params);
    REQUIRE(relaxed.positions.size() == 1500);
    for (std::size_t i = 0; i < relaxed.positions.size(); ++i) {
        CHECK(relaxed.positions[i].length() == Approx(1.0).margin(1e-9));
        int x, y;
        grid.pixelOf(relaxed.scalp[i].x(), relaxed.scalp[i].y(), x, y);
        CHECK(mask.isValid(x, y));
    }
    params.iterations = 0;
    const ScatteredRoots random = scatterRoots(unitMap(), grid, mask, params);
    std::vector<Vec3f> a(relaxed.positions.begin(), relaxed.positions.end()), b(random.positions.begin(), random.positions.end());
    const FollicleStats sa = measureFollicles(a), sb = measureFollicles(b);
    CAPTURE(sa.nnCV, sb.nnCV);
    CHECK(sa.nnCV < 0.6 * sb.nnCV);
    CHECK(sa.nnCV < 0.25);
    // The area of the region (a cap of the unit sphere from y = 0.375 up, padded by the mask) is
    // near the cap's 2 pi (1 - 0.375).
    CHECK(relaxed.area == Approx(2 * M_PI * 0.625).epsilon(0.15));
    params.iterations = 10;
    const ScatteredRoots again = scatterRoots(unitMap(), grid, mask, params, false);
    CHECK(again.positions == relaxed.positions);
    params.count = 0;
    CHECK_THROWS_WITH(scatterRoots(unitMap(), grid, mask, params), Catch::Contains("count of 0"));
}

TEST_CASE("rootDensity and scatterRoots: new roots at the example's density, place by place", "[synth]")
{
    // An example four times as dense on one side of the cap (u below the split) as on the other.
    const auto& [coords, split, grid, mask] = denseSparseExample();
    const FeatureImage density = rootDensity(grid, coords, mask);
    REQUIRE(density.channels == 1);
    // Away from the split, the densities stand as the example's (4 : 1).
    double dense = 0.0, sparse = 0.0;
    std::size_t nd = 0, ns = 0;
    for (int y = 0; y < grid.height; ++y)
        for (int x = 0; x < grid.width; ++x) {
            if (!mask.isValid(x, y)) {
                CHECK_FALSE(density.isValid(x, y));
                continue;
            }
            const double u = grid.u(x);
            if (u < split - 0.2) dense += density.pixel(x, y)[0], ++nd;
            if (u > split + 0.2) sparse += density.pixel(x, y)[0], ++ns;
        }
    REQUIRE(nd > 50);
    REQUIRE(ns > 50);
    CHECK(dense / double(nd) / (sparse / double(ns)) == Approx(4.0).epsilon(0.2));
    // The new roots keep the sides' shares, relaxed or not, and the dense side's spacing is half
    // the sparse side's; the result does not depend on threads.
    RootScatterParams params;
    params.count = 1500;
    params.seed = 5;
    const auto share = [split = split](const ScatteredRoots& r) {
        std::size_t left = 0;
        for (const Vec3d& s : r.scalp) left += s.x() < split;
        return double(left) / double(r.scalp.size());
    };
    const double exampleShare = double(std::count_if(coords.begin(), coords.end(), [split = split](const Vec3d& c) { return c.x() < split; })) / double(coords.size());
    const ScatteredRoots even = scatterRoots(unitMap(), grid, mask, params);
    const ScatteredRoots relaxed = scatterRoots(unitMap(), grid, mask, params, true, &density);
    CAPTURE(exampleShare, share(even), share(relaxed));
    CHECK(share(even) == Approx(0.5).margin(0.08));
    CHECK(share(relaxed) == Approx(exampleShare).margin(0.05));
    CHECK(scatterRoots(unitMap(), grid, mask, params, false, &density).positions == relaxed.positions);
    const auto [sl, sr] = sideSpacings(relaxed, split);
    CAPTURE(sl.nnMean, sr.nnMean, sl.nnCV, sr.nnCV);
    CHECK(sr.nnMean / sl.nnMean == Approx(2.0).epsilon(0.25));
    CHECK(sl.nnCV < 0.35);
    CHECK(sr.nnCV < 0.35);
    params.iterations = 0;
    CHECK(share(scatterRoots(unitMap(), grid, mask, params, true, &density)) == Approx(exampleShare).margin(0.05));
    CHECK_THROWS_WITH(rootDensity(grid, {}, mask), Catch::Contains("no coordinates"));
}

TEST_CASE("scatterAroundRoots: new roots where the example's are, each side's share kept, deterministic", "[synth]")
{
    // The example of the test above: four times as dense where u is below the split.
    const auto& [coords, split, grid, mask] = denseSparseExample();
    const auto leftShare = [split = split](const std::vector<Vec3d>& uv) {
        return double(std::count_if(uv.begin(), uv.end(), [&](const Vec3d& c) { return c.x() < split; })) / double(uv.size());
    };
    const double exampleShare = leftShare(coords);
    // The distance in (u, v) from each new root to the nearest example root, over that root's
    // distance to its own nearest neighbour.
    std::vector<Vec3d> flat;
    for (const Vec3d& c : coords) flat.emplace_back(c.x(), c.y(), 0.0);
    const auto nearest = [&](const Vec3d& q, std::size_t skip) {
        double best = 1e300;
        std::size_t at = 0;
        for (std::size_t j = 0; j < flat.size(); ++j) {
            const double d = (Vec3d(q.x(), q.y(), 0.0) - flat[j]).length();
            if (j != skip && d < best) best = d, at = j;
        }
        return std::make_pair(best, at);
    };
    RootScatterParams params;
    params.count = coords.size();
    params.seed = 5;
    const ScatteredRoots once = scatterAroundRoots(unitMap(), grid, mask, coords, params);
    REQUIRE(once.scalp.size() == coords.size());
    CAPTURE(exampleShare, leftShare(once.scalp));
    // As many new roots as example roots: each side's share is the example's up to the few roots
    // within half a spacing of the split; none strays further than half its example root's spacing
    // from it, and few sit on an example root (they are new).
    CHECK(leftShare(once.scalp) == Approx(exampleShare).margin(0.01));
    std::size_t onRoot = 0;
    for (std::size_t i = 0; i < once.scalp.size(); i += 7) {
        CHECK(once.positions[i].length() == Approx(1.0).margin(1e-9));
        const auto [d, j] = nearest(once.scalp[i], flat.size());
        const double spacing = nearest(flat[j], j).first;
        CHECK(d <= kAroundReach * spacing * 1.5 + 1e-12);
        onRoot += d < 0.05 * spacing;
    }
    CHECK(onRoot < once.scalp.size() / 7 / 20);
    CHECK(scatterAroundRoots(unitMap(), grid, mask, coords, params, false).positions == once.positions);
    // Three times as many: drawn round three times and relaxed at the example's density, so the
    // shares and the 2 : 1 spacing stand and the repeats spread out.
    params.count = 3 * coords.size();
    const ScatteredRoots more = scatterAroundRoots(unitMap(), grid, mask, coords, params);
    CAPTURE(leftShare(more.scalp));
    CHECK(leftShare(more.scalp) == Approx(exampleShare).margin(0.03));
    const auto [sl, sr] = sideSpacings(more, split);
    CAPTURE(sl.nnMean, sr.nnMean, sl.nnCV, sr.nnCV);
    CHECK(sr.nnMean / sl.nnMean == Approx(2.0).epsilon(0.25));
    CHECK(sl.nnCV < 0.4);
    CHECK(sr.nnCV < 0.4);
    CHECK(scatterAroundRoots(unitMap(), grid, mask, coords, params, false).positions == more.positions);
    params.count = 0;
    CHECK_THROWS_WITH(scatterAroundRoots(unitMap(), grid, mask, coords, params), Catch::Contains("count of 0"));
    params.count = 10;
    CHECK_THROWS_WITH(scatterAroundRoots(unitMap(), grid, mask, {}, params), Catch::Contains("no example roots"));
}
