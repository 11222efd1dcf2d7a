#include <vdbhair/Exceptions.h>
#include <vdbhair/dataset/Prepare.h>
#include <vdbhair/io/MeshFile.h>
#include <vdbhair/io/StrandIO.h>
#include <vdbhair/scalp/HeadFile.h>
#include <vdbhair/strands/Measures.h>
#include <vdbhair/strands/Resample.h>

#include "TestUtil.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>

using namespace vdbhair;
using Catch::Matchers::Contains;

namespace {

/// Strands rooted on the upper half of the unit sphere, each a straight line tangent-ish to it and
/// aimed 30 degrees into it, so every one passes through the sphere (like hair combed into a head).
StrandSet strandsIntoSphere(int n)
{
    StrandSet s;
    const double pi = 3.14159265358979323846;
    for (int i = 0; i < n; ++i) {
        const double phi = 2.0 * pi * i / n, theta = 0.2 + 0.8 * (i % 7) / 7.0;
        const Vec3d root(std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi));
        Vec3d tangent = Vec3d(0, 1, 0).cross(root).cross(root);  // downhill along the sphere
        tangent.normalize();
        const Vec3d dir = (tangent * std::cos(0.5) - root * std::sin(0.5)).unit();
        std::vector<Vec3f> pts;
        for (int k = 0; k < 13 + i % 5; ++k) {
            const Vec3d p = root * 1.001 + dir * (0.1 * k);
            pts.emplace_back(float(p.x()), float(p.y()), float(p.z()));
        }
        s.addStrand(pts);
    }
    return s;
}

} // namespace

TEST_CASE("prepareStrands: --points gives exactly N points per strand with root and tip kept", "[dataset]")
{
    StrandSet s = test::sampleStrands();
    const StrandSet before = s;
    PrepareParams p;
    p.points = 100;
    const PrepareReport r = prepareStrands(s, p, nullptr, nullptr, nullptr);
    REQUIRE(s.numStrands() == before.numStrands());
    CHECK(r.vertices == 100 * before.numStrands());
    for (std::size_t i = 0; i < s.numStrands(); ++i) {
        CAPTURE(i);
        CHECK(s.size(i) == 100);
        CHECK(s.root(i) == before.root(i));
        CHECK((s.tip(i) - before.tip(i)).length() < 1e-6f);
        CHECK(polylineLength(s.data(i), s.size(i)) <= polylineLength(before.data(i), before.size(i)) + 1e-5);
    }
}

TEST_CASE("prepareStrands: --fix-penetration leaves no vertex inside a sphere head", "[dataset]")
{
    StrandSet s = strandsIntoSphere(60);
    const HeadObstacle head = HeadObstacle::sphere(Vec3d(0.0), 1.0);
    REQUIRE(countStrandsEnteringHead(s, head, 0.0) == 60);
    PrepareParams p;
    p.points = 32;
    const std::vector<float> lengths = strandLengths(resampleStrands(s, 32));
    const PrepareReport r = prepareStrands(s, p, nullptr, nullptr, &head);
    CHECK(r.fixed);
    CHECK(r.enteringBefore == 60);
    CHECK(r.enteringAfter == 0);
    CHECK(r.collision.verticesTooDeep == 0);
    HeadObstacle::Probe probe(head);
    double deepest = 0.0;
    for (const Vec3f& v : s.positions) deepest = std::min(deepest, probe.distance(Vec3d(v.x(), v.y(), v.z())));
    CHECK(deepest > -1e-5);
    // Lengths and vertex counts are kept.
    const std::vector<float> after = strandLengths(s);
    for (std::size_t i = 0; i < s.numStrands(); ++i) {
        CHECK(s.size(i) == 32);
        CHECK(after[i] == Approx(lengths[i]).epsilon(1e-4));
    }
}

TEST_CASE("prepareStrands: --root-depth surface lifts strands rooted inside a sphere head onto it", "[dataset]")
{
    // Strands rooted 0.1 inside the unit sphere, straight out and on through it again.
    StrandSet s;
    for (int i = 0; i < 12; ++i) {
        const double a = 0.5 * i;
        const Vec3d root = Vec3d(std::cos(a), 0.3, std::sin(a)).unit() * 0.9;
        const Vec3d dir = Vec3d(-std::sin(a), -0.2, std::cos(a)).unit();
        std::vector<Vec3f> pts;
        for (int k = 0; k < 20; ++k) {
            const Vec3d p = root + dir * (0.1 * k);
            pts.emplace_back(float(p.x()), float(p.y()), float(p.z()));
        }
        s.addStrand(pts);
    }
    const HeadObstacle head = HeadObstacle::sphere(Vec3d(0.0), 1.0);
    StrandSet kept = s;
    PrepareParams keep;
    prepareStrands(kept, keep, nullptr, nullptr, &head);
    PrepareParams lift;
    lift.rootDepth = RootDepth::Surface;
    const PrepareReport r = prepareStrands(s, lift, nullptr, nullptr, &head);
    CHECK(r.rootsLifted == 12);
    HeadObstacle::Probe probe(head);
    double deepest = 0.0, deepestKept = 0.0;
    for (const Vec3f& v : s.positions) deepest = std::min(deepest, probe.distance(Vec3d(v.x(), v.y(), v.z())));
    for (const Vec3f& v : kept.positions) deepestKept = std::min(deepestKept, probe.distance(Vec3d(v.x(), v.y(), v.z())));
    CHECK(deepest > -1e-5);
    CHECK(deepestKept < -0.09);  // keep: as deep as the roots
    // On the surface, as pushOut() places a point: just outside it (1e-4 of the radius here).
    for (std::size_t i = 0; i < s.numStrands(); ++i) CHECK(Vec3d(s.root(i)).length() == Approx(1.0).margin(2e-4));
    REQUIRE_THROWS_WITH(rootDepthFromName("deep"), Contains("root_depth 'deep': must be keep or surface"));
}

TEST_CASE("prepareStrands: aligning a groom's head to a moved copy moves the strands by that transform", "[dataset]")
{
    // The head: a coarse sphere mesh; the target: the same mesh scaled, turned and moved.
    TriangleMesh head;
    const int rings = 12, segs = 16;
    for (int i = 0; i <= rings; ++i) {
        for (int j = 0; j < segs; ++j) {
            const double t = 3.14159265 * i / rings, f = 6.2831853 * j / segs;
            head.vertices.emplace_back(float(0.9 * std::sin(t) * std::cos(f)), float(std::cos(t) + 0.1 * std::cos(f)), float(std::sin(t) * std::sin(f)));
        }
    }
    for (int i = 0; i < rings; ++i) {
        for (int j = 0; j < segs; ++j) {
            const std::uint32_t a = std::uint32_t(i * segs + j), b = std::uint32_t(i * segs + (j + 1) % segs);
            head.triangles.push_back({a, a + segs, b});
            head.triangles.push_back({b, a + segs, b + segs});
        }
    }
    Similarity truth;
    truth.scale = 0.12;
    truth.rotation = openvdb::math::rotation<openvdb::math::Mat3d>(openvdb::math::Y_AXIS, 0.7);
    truth.translation = Vec3d(0.0, 1.7, 0.01);
    TriangleMesh target = head;
    for (Vec3f& v : target.vertices) {
        const Vec3d q = truth.apply(Vec3d(v.x(), v.y(), v.z()));
        v = Vec3f(float(q.x()), float(q.y()), float(q.z()));
    }
    StrandSet s = test::sampleStrands();
    const StrandSet before = s;
    PrepareParams p;
    const PrepareReport r = prepareStrands(s, p, &head, &target, nullptr);
    REQUIRE(r.align);
    CHECK(r.align->transform.scale == Approx(0.12).epsilon(1e-6));
    CHECK(r.align->rms < 1e-6);
    for (std::size_t v = 0; v < s.numVertices(); ++v) {
        const Vec3d q = truth.apply(Vec3d(before.positions[v].x(), before.positions[v].y(), before.positions[v].z()));
        CAPTURE(v);
        CHECK((Vec3d(s.positions[v].x(), s.positions[v].y(), s.positions[v].z()) - q).length() < 1e-5);
        CHECK(s.thickness[v] == Approx(before.thickness[v] * 0.12).epsilon(1e-5));
    }
    // The JSON report carries the transform and the residual.
    const nlohmann::json j = toJson(r);
    CHECK(j["align"]["method"] == "correspondence");
    CHECK(j["align"]["matrix"].size() == 4);
    CHECK(j["align"]["residual_rms"].get<double>() < 1e-6);
}

TEST_CASE("prepareStrands: --strands keeps N with even roots; bad parameters are refused with the rule", "[dataset]")
{
    StrandSet s = strandsIntoSphere(200);
    PrepareParams p;
    p.strands = 50;
    const PrepareReport r = prepareStrands(s, p, nullptr, nullptr, nullptr);
    CHECK(s.numStrands() == 50);
    REQUIRE(r.subsample);
    CHECK(r.subsample->minSpacing >= r.subsample->coverageRadius);

    PrepareParams one;
    one.points = 1;
    REQUIRE_THROWS_WITH(prepareStrands(s, one, nullptr, nullptr, nullptr), Contains("points 1: a strand needs at least 2 vertices"));
    PrepareParams huge;
    huge.points = std::size_t(1) << 40;
    REQUIRE_THROWS_WITH(prepareStrands(s, huge, nullptr, nullptr, nullptr), Contains("exceed the limit of 2^32-1 vertices"));
    TriangleMesh target;
    REQUIRE_THROWS_WITH(prepareStrands(s, PrepareParams{}, nullptr, &target, nullptr), Contains("needs the groom's own head mesh"));
}

TEST_CASE("prepareStrands: the USC guide sets on the USC head (real data)", "[dataset][data]")
{
    VDBHAIR_REQUIRE_SHARED_DATA();
    const std::string hair = test::sharedData() + "/hair/usc_data/hairnet_cstrands/cstrands00001.data";
    const std::string headPath = test::sharedData() + "/scalp/usc_hairsalon/head_model.ply";
    if (!std::filesystem::exists(hair) || !std::filesystem::exists(headPath)) {
        WARN("SKIPPED: " << hair << " or " << headPath << " is not there");
        return;
    }
    StrandSet s = readStrands(hair);
    const TriangleMesh head = readTriangleMesh(headPath);
    PrepareParams p;
    p.points = 100;
    p.strands = 4;
    const HeadObstacle obstacle = readHeadObstacle(headPath, "head", HeadPolicy::KeepOutside);
    const PrepareReport r = prepareStrands(s, p, &head, &head, &obstacle);
    CHECK(s.numStrands() == 4);
    CHECK(s.numVertices() == 400);
    REQUIRE(r.align);
    CHECK(r.align->method == AlignMethod::Correspondence);
    CHECK(r.align->transform.scale == Approx(1.0).margin(1e-9));
    CHECK(r.enteringAfter == 0);
}
