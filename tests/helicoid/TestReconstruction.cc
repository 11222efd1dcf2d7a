#include "../TestUtil.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/field/HeadCollision.h>
#include <vdbhair/helicoid/Reconstruction.h>
#include <vdbhair/io/StrandIO.h>
#include <vdbhair/strands/Resample.h>

#include <tbb/global_control.h>

#include <cmath>
#include <filesystem>
#include <random>

using namespace vdbhair;
using Catch::Matchers::Contains;

namespace {

/// 60 strands grown from random helicoids on a 6 by 10 patch, resampled to 30 vertices.
StrandSet patch()
{
    Scene scene;
    scene.step = 0.02;
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (int i = 0; i < 60; ++i) {
        SceneGuide g;
        g.root = Vec3d(0.1 * (i % 6), 0.1 * (i / 6), 0.0);
        g.frame = FrameD::fromTangentNormal(Vec3d(0.1 * u(rng), 0.1 * u(rng), 1.0), Vec3d(1, 0, 0));
        HelicoidPiece p;
        p.k = {1.0 + 0.2 * u(rng), 0.1 * u(rng), 0.2 * u(rng), 0.1 * u(rng)};
        p.length = 2.0;
        g.pieces.push_back(p);
        scene.guides.push_back(g);
    }
    return resampleStrands(growScene(scene), 30);
}

} // namespace

TEST_CASE("selectGuides: the share asked for, ascending and distinct; bad shares refused", "[helicoid][interp]")
{
    const StrandSet s = patch();
    for (GuideSelection sel : {GuideSelection::Random, GuideSelection::Cluster}) {
        const std::vector<std::size_t> g = selectGuides(s, 0.1, sel, 3);
        REQUIRE(g.size() == 6u);
        for (std::size_t i = 1; i < g.size(); ++i) REQUIRE(g[i - 1] < g[i]);
        REQUIRE(selectGuides(s, 0.1, sel, 3) == g);
    }
    REQUIRE(selectGuides(s, 1.0, GuideSelection::Random, 0).size() == 60u);
    REQUIRE_THROWS_WITH(selectGuides(s, 0.0, GuideSelection::Random, 0), Contains("must be more than 0 % and at most 100 %"));
    REQUIRE_THROWS_WITH(selectGuides(s, 1.5, GuideSelection::Random, 0), Contains("guides 150 %"));
}

TEST_CASE("reconstructHairstyle: 100 % guides reproduce the fits' own error; 10 % is finite for every strand", "[helicoid][interp]")
{
    const StrandSet s = patch();
    ReconstructParams all;
    all.guideFraction = 1.0;
    const ReconstructResult r = reconstructHairstyle(s, all);
    REQUIRE(r.guides.size() == 60u);
    REQUIRE(r.helicoidErrors.mean == Approx(r.fitSummary.meanRelative).epsilon(1e-4));
    REQUIRE(r.helicoidErrors.p95 == Approx(r.fitSummary.p95Relative).epsilon(1e-4));
    REQUIRE(r.pointErrors.mean == 0.0);  // the points way keeps guides as they are

    ReconstructParams tenth;
    tenth.guideFraction = 0.1;
    const ReconstructResult t = reconstructHairstyle(s, tenth);
    REQUIRE(t.helicoid.numStrands() == 60u);
    REQUIRE(t.points.numStrands() == 60u);
    REQUIRE(t.helicoidErrors.relative.size() == 60u);
    for (std::size_t i = 0; i < 60; ++i) {
        CAPTURE(i);
        REQUIRE(std::isfinite(t.helicoidErrors.relative[i]));
        REQUIRE(std::isfinite(t.pointErrors.relative[i]));
        REQUIRE(t.helicoid.root(i) == s.root(i));
    }
    CAPTURE(t.helicoidErrors.meanInterpolated, t.pointErrors.meanInterpolated);
    REQUIRE(t.helicoidErrors.meanInterpolated > 0.0);
    REQUIRE(t.helicoidErrors.meanInterpolated < 0.2);  // similar helicoids on a small patch
    // Identical for 1 and 2 threads.
    ReconstructResult one;
    {
        tbb::global_control c(tbb::global_control::max_allowed_parallelism, 1);
        one = reconstructHairstyle(s, tenth);
    }
    REQUIRE(one.helicoid.positions == t.helicoid.positions);
    REQUIRE(one.points.positions == t.points.positions);
    REQUIRE(one.helicoidErrors.relative == t.helicoidErrors.relative);
}

TEST_CASE("reconstructHairstyle: real straight hair at 10 % guides", "[helicoid][interp][data]")
{
    VDBHAIR_REQUIRE_SHARED_DATA();
    const std::string path = test::sharedData() + "/hair/cyhair/straight.hair";
    if (!std::filesystem::exists(path)) {
        WARN("SKIPPED: " << path << " is not available");
        return;
    }
    const StrandSet all = readStrands(path);
    // Every tenth strand (1,000), resampled to 30 vertices: a quick but real case.
    StrandSet some;
    for (std::size_t i = 0; i < all.numStrands(); i += 10) {
        some.addStrand(std::vector<Vec3f>(all.positions.begin() + std::ptrdiff_t(all.begin(i)), all.positions.begin() + std::ptrdiff_t(all.begin(i) + all.size(i))));
    }
    some = resampleStrands(some, 30);
    const ReconstructResult r = reconstructHairstyle(some, ReconstructParams{});
    std::cout << "straight.hair (1,000 strands) at 10 % guides: helicoid mean " << r.helicoidErrors.meanInterpolated
              << " p95 " << r.helicoidErrors.p95Interpolated << "; points mean " << r.pointErrors.meanInterpolated << " p95 "
              << r.pointErrors.p95Interpolated << " (interpolated strands, fraction of length)\n";
    // Every strand is reported, finitely; the errors themselves are measured, not asserted here
    // (docs/interpolation.md: helicoid blending of independent fits misses the
    // issue's goal on real hair).
    REQUIRE(r.helicoidErrors.relative.size() == some.numStrands());
    REQUIRE(r.guides.size() == 100u);
    for (double e : r.helicoidErrors.relative) REQUIRE(std::isfinite(e));
    for (double e : r.pointErrors.relative) REQUIRE(std::isfinite(e));
    REQUIRE(r.pointErrors.meanInterpolated < 0.1);  // neighbouring straight strands are alike
    // The fits' own pieces blended (the paper's rule, interpolation's default) against the arcs
    // reconstruction chooses: arcs follow the captured strands more closely.
    ReconstructParams fitted;
    fitted.helicoid.blend = HelicoidBlend::Fitted;
    const ReconstructResult f = reconstructHairstyle(some, fitted);
    std::cout << "  the same with --blend fitted: helicoid mean " << f.helicoidErrors.meanInterpolated << " p95 "
              << f.helicoidErrors.p95Interpolated << "\n";
    REQUIRE(r.helicoidErrors.meanInterpolated < f.helicoidErrors.meanInterpolated);
}

TEST_CASE("reconstructHairstyle: the shares leaving the guides' volume and passing into a head", "[helicoid][interp]")
{
    // 400 straight strands hanging down (-z) from a 20 x 20 grid of roots at z = 0, x in [0, 1.9],
    // y in [-0.95, 0.95]; a head sphere of radius 1.5 about (0, 0, -2) below. Parallel guides give
    // every strand back exactly by points, so the points way passes into the head exactly where
    // the original does: where the root lies within 1.5 (less the tolerance) of the z axis.
    StrandSet s;
    for (int i = 0; i < 20; ++i)
        for (int j = 0; j < 20; ++j) {
            std::vector<Vec3f> p(41);
            for (int k = 0; k < 41; ++k) p[k] = Vec3f(0.1f * float(i), -0.95f + 0.1f * float(j), -0.1f * float(k));
            s.addStrand(p);
        }
    const HeadObstacle head = HeadObstacle::sphere(Vec3d(0.0, 0.0, -2.0), 1.5);
    ReconstructParams params;
    const ReconstructResult r = reconstructHairstyle(s, params, true, nullptr, &head);
    REQUIRE(r.headMeasured);
    CHECK(r.volumeVoxel > 0.0);
    std::vector<char> isGuide(s.numStrands(), 0);
    for (std::size_t g : r.guides) isGuide[g] = 1;
    const double tol = headTolerance(head);
    std::size_t inside = 0, others = 0;
    for (std::size_t i = 0; i < s.numStrands(); ++i) {
        if (isGuide[i]) continue;
        ++others;
        const Vec3f root = s.root(i);
        if (std::hypot(double(root.x()), double(root.y())) < 1.5 - tol) ++inside;
    }
    REQUIRE(inside > 0);
    REQUIRE(inside < others);
    CHECK(r.originalEnteringHead == Approx(double(inside) / double(others)));
    CHECK(r.pointErrors.enteringHead == Approx(r.originalEnteringHead));
    CHECK(r.originalLeavingVolume == 0.0);  // the groom fills its own guides' volume
    CHECK(r.pointErrors.leavingVolume == 0.0);
    CHECK(r.nearestErrors.leavingVolume == 0.0);
    const ReconstructResult none = reconstructHairstyle(s, params);
    CHECK_FALSE(none.headMeasured);
    CHECK(none.pointErrors.enteringHead == 0.0);
}
