#include <vdbhair/Exceptions.h>
#include <vdbhair/dataset/SimilarityAlign.h>

#include "TestUtil.h"

#include <catch2/catch.hpp>

#include <tbb/global_control.h>

#include <cmath>
#include <random>
#include <vector>

using namespace vdbhair;
using Catch::Matchers::Contains;

namespace {

/// The rotation of @a angle radians about the unit axis @a axis (Rodrigues).
openvdb::math::Mat3d rotationAbout(Vec3d axis, double angle)
{
    axis.normalize();
    const double c = std::cos(angle), s = std::sin(angle), t = 1.0 - c;
    const double x = axis.x(), y = axis.y(), z = axis.z();
    openvdb::math::Mat3d m;
    m(0, 0) = t * x * x + c;     m(0, 1) = t * x * y - s * z; m(0, 2) = t * x * z + s * y;
    m(1, 0) = t * x * y + s * z; m(1, 1) = t * y * y + c;     m(1, 2) = t * y * z - s * x;
    m(2, 0) = t * x * z - s * y; m(2, 1) = t * y * z + s * x; m(2, 2) = t * z * z + c;
    return m;
}

/// A closed, head-sized lump with no rotational symmetry: an ellipsoid (radii 0.8, 1, 0.9) with a
/// "nose" at +z and a bump at the upper right back, as a UV sphere of @a rings x @a segments.
TriangleMesh lumpyHead(int rings = 40, int segments = 60)
{
    TriangleMesh m;
    auto bump = [](const Vec3d& d, const Vec3d& centre, double width) {
        return std::exp(-(d - centre).lengthSqr() / (width * width));
    };
    const double pi = 3.14159265358979323846;
    for (int i = 0; i <= rings; ++i) {
        const double theta = pi * i / rings;
        for (int j = 0; j < segments; ++j) {
            const double phi = 2.0 * pi * j / segments;
            const Vec3d d(std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi));
            const double r = 1.0 + 0.4 * bump(d, Vec3d(0, 0, 1), 0.35) + 0.25 * bump(d, Vec3d(0.6, 0.6, -0.5).unit(), 0.5);
            m.vertices.emplace_back(float(0.8 * r * d.x()), float(r * d.y()), float(0.9 * r * d.z()));
        }
    }
    for (int i = 0; i < rings; ++i) {
        for (int j = 0; j < segments; ++j) {
            const std::uint32_t a = std::uint32_t(i * segments + j), b = std::uint32_t(i * segments + (j + 1) % segments);
            const std::uint32_t c = a + std::uint32_t(segments), d = b + std::uint32_t(segments);
            m.triangles.push_back({a, c, b});
            m.triangles.push_back({b, c, d});
        }
    }
    return m;
}

TriangleMesh transformed(const TriangleMesh& m, const Similarity& t)
{
    TriangleMesh out = m;
    for (Vec3f& v : out.vertices) {
        const Vec3d q = t.apply(Vec3d(v.x(), v.y(), v.z()));
        v = Vec3f(float(q.x()), float(q.y()), float(q.z()));
    }
    return out;
}

std::vector<Vec3d> toD(const std::vector<Vec3f>& v)
{
    std::vector<Vec3d> out;
    for (const Vec3f& p : v) out.emplace_back(p.x(), p.y(), p.z());
    return out;
}

/// The largest difference between the 4x4 matrices of @a a and @a b, each entry relative to @a size
/// for the translation column.
double matrixDifference(const Similarity& a, const Similarity& b, double size)
{
    double worst = std::abs(a.scale - b.scale) / b.scale;
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) worst = std::max(worst, std::abs(a.rotation(i, j) - b.rotation(i, j)));
        worst = std::max(worst, std::abs(a.translation[i] - b.translation[i]) / size);
    }
    return worst;
}

} // namespace

TEST_CASE("fitSimilarity: recovers a known scale, rotation and translation from exact pairs", "[dataset]")
{
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (double scale : {1e-3, 0.37, 1.0, 2.5, 400.0}) {
        Similarity truth;
        truth.scale = scale;
        truth.rotation = rotationAbout(Vec3d(u(rng), u(rng), u(rng)), 3.0 * u(rng));
        truth.translation = Vec3d(u(rng), u(rng), u(rng)) * 10.0;
        std::vector<Vec3d> from, to;
        for (int i = 0; i < 50; ++i) {
            from.emplace_back(u(rng), u(rng), u(rng));
            to.push_back(truth.apply(from.back()));
        }
        const Similarity fit = fitSimilarity(from, to);
        CAPTURE(scale);
        CHECK(matrixDifference(fit, truth, 10.0) < 1e-9);
        CHECK(fit.rotation.det() == Approx(1.0).margin(1e-12));
        // and back
        const Similarity inv = fit.inverse();
        CHECK((inv.apply(to[3]) - from[3]).length() < 1e-9);
    }
}

TEST_CASE("fitSimilarity: bad pairs are refused with the rule", "[dataset]")
{
    const std::vector<Vec3d> three{Vec3d(0.0), Vec3d(1, 0, 0), Vec3d(0, 1, 0)};
    REQUIRE_THROWS_WITH(fitSimilarity(three, {Vec3d(0.0)}), Contains("the counts must agree"));
    REQUIRE_THROWS_WITH(fitSimilarity({Vec3d(0.0), Vec3d(1.0)}, {Vec3d(0.0), Vec3d(1.0)}), Contains("at least 3"));
    const std::vector<Vec3d> same(3, Vec3d(1.0));
    REQUIRE_THROWS_AS(fitSimilarity(same, three), ValueError);
}

TEST_CASE("alignMeshes: a moved copy of a head is recovered exactly, by correspondence and by ICP", "[dataset]")
{
    const TriangleMesh head = lumpyHead();
    Similarity truth;
    truth.scale = 0.01;  // a head in centimetres moved into metres
    truth.rotation = rotationAbout(Vec3d(0.3, 1.0, -0.2), 0.45);
    truth.translation = Vec3d(0.02, 1.7, -0.05);
    const TriangleMesh target = transformed(head, truth);

    SECTION("same vertices and triangles: Umeyama on vertex pairs")
    {
        const AlignResult r = alignMeshes(head, target);
        CHECK(r.method == AlignMethod::Correspondence);
        CHECK(matrixDifference(r.transform, truth, 0.01) < 1e-6);
        CHECK(r.rms < 1e-7);
    }
    // ICP's oracle: a transform whose image float coordinates hold to 1e-7 of the head's size.
    Similarity icpTruth;
    icpTruth.scale = 2.0;
    icpTruth.rotation = truth.rotation;
    icpTruth.translation = Vec3d(0.5, -0.25, 0.125);
    SECTION("the triangles listed in another order: trimmed ICP from the axis rotations")
    {
        TriangleMesh shuffled = transformed(head, icpTruth);
        std::reverse(shuffled.triangles.begin(), shuffled.triangles.end());
        const AlignResult r = alignMeshes(head, shuffled);
        CHECK(r.method == AlignMethod::Icp);
        CAPTURE(r.rms, r.iterations, r.start);
        CHECK(matrixDifference(r.transform, icpTruth, 1.0) < 1e-6);
        CHECK(r.rms < 1e-6);
    }
    SECTION("z up, as cyHair's heads: a quarter turn the starts find")
    {
        Similarity zUp = icpTruth;
        zUp.rotation = rotationAbout(Vec3d(1, 0, 0), -1.5707963267948966) * rotationAbout(Vec3d(0, 1, 0), 0.3);
        TriangleMesh moved = transformed(head, zUp);
        std::reverse(moved.triangles.begin(), moved.triangles.end());
        const AlignResult r = alignMeshes(head, moved);
        CAPTURE(r.rms, r.start, r.iterations);
        CHECK(r.method == AlignMethod::Icp);
        CHECK(matrixDifference(r.transform, zUp, 1.0) < 1e-6);
    }
}

TEST_CASE("alignMeshes: a head cut lower is aligned to the whole head", "[dataset]")
{
    const TriangleMesh head = lumpyHead(60, 90);
    Similarity truth;
    truth.scale = 1.3;
    truth.rotation = rotationAbout(Vec3d(0.0, 1.0, 0.1), -0.3);
    truth.translation = Vec3d(0.5, -0.2, 0.1);
    // The source keeps the vertices above y = -0.95 (90 %) and the triangles between them (the target has
    // the whole lump): fewer unmatched target points than the 15 % of pairs that trimming drops.
    TriangleMesh cut;
    std::vector<std::uint32_t> index(head.vertices.size(), ~0u);
    for (std::size_t i = 0; i < head.vertices.size(); ++i) {
        if (head.vertices[i].y() <= -0.95f) continue;
        index[i] = std::uint32_t(cut.vertices.size());
        cut.vertices.push_back(head.vertices[i]);
    }
    for (const auto& t : head.triangles) {
        if (index[t[0]] != ~0u && index[t[1]] != ~0u && index[t[2]] != ~0u) cut.triangles.push_back({index[t[0]], index[t[1]], index[t[2]]});
    }
    const AlignResult r = alignMeshes(cut, transformed(head, truth));
    CAPTURE(r.rms, r.start, r.iterations, cut.vertices.size(), head.vertices.size());
    CHECK(matrixDifference(r.transform, truth, 1.0) < 1e-6);
}

TEST_CASE("alignPointSets: identical for 1 and 2 threads; bad input refused", "[dataset]")
{
    const TriangleMesh head = lumpyHead(20, 30);
    std::vector<Vec3d> from = toD(head.vertices), to;
    Similarity t;
    t.scale = 2.0;
    t.rotation = rotationAbout(Vec3d(1, 1, 0), 0.2);
    for (const Vec3d& p : from) to.push_back(t.apply(p) + Vec3d(0.001 * std::sin(p.x() * 40.0)));  // not exact: a real residual
    AlignResult r[2];
    for (int threads : {1, 2}) {
        tbb::global_control c(tbb::global_control::max_allowed_parallelism, std::size_t(threads));
        r[threads - 1] = alignPointSets(from, to);
    }
    CHECK(r[0].rms == r[1].rms);
    CHECK(r[0].transform.scale == r[1].transform.scale);
    CHECK(r[0].transform.translation == r[1].transform.translation);
    CHECK(r[0].rms > 0.0);

    REQUIRE_THROWS_WITH(alignPointSets({Vec3d(0.0), Vec3d(1.0)}, to), Contains("the source has 2 points; at least 3"));
    std::vector<Vec3d> bad = to;
    bad[5] = Vec3d(std::nan(""), 0.0, 0.0);
    REQUIRE_THROWS_WITH(alignPointSets(from, bad), Contains("the target point 5 is not finite"));
    AlignParams p;
    p.overlap = 0.0;
    REQUIRE_THROWS_WITH(alignPointSets(from, to, p), Contains("overlap 0: must be in (0, 1]"));
}
