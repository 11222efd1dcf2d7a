#include "../TestUtil.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/io/HairFile.h>
#include <vdbhair/io/MeshFile.h>
#include <vdbhair/io/RootEnd.h>
#include <vdbhair/io/StrandIO.h>
#include <vdbhair/strands/PointCloud.h>

#include <cmath>
#include <memory>
#include <random>

using namespace vdbhair;
using Catch::Matchers::Contains;

namespace {

/// A hairstyle on a head (a sphere of radius @a r at @a c): @a n roots spread over the upper
/// half, each strand leaving along the normal, then hanging under gravity (-Y) for its length.
StrandSet hairOnSphere(std::size_t n, const Vec3f& c, float r, unsigned seed)
{
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0.f, 1.f);
    StrandSet s;
    for (std::size_t i = 0; i < n; ++i) {
        const float phi = 2.f * float(M_PI) * u(rng), cosTheta = 0.1f + 0.9f * u(rng);
        const float sinTheta = std::sqrt(1.f - cosTheta * cosTheta);
        const Vec3f normal(sinTheta * std::cos(phi), cosTheta, sinTheta * std::sin(phi));
        const float length = r * (0.5f + 2.f * u(rng));
        std::vector<Vec3f> pts;
        Vec3f p = c + r * normal;
        for (int k = 0; k < 16; ++k) {
            pts.push_back(p);
            const float t = float(k) / 15.f;
            Vec3f dir = (1.f - t) * normal + t * Vec3f(0.f, -1.f, 0.f);
            dir.normalize();
            p += (length / 15.f) * dir;
        }
        s.addStrand(pts);
    }
    return s;
}

StrandSet reversed(StrandSet s)
{
    for (std::size_t i = 0; i < s.numStrands(); ++i) reverseStrand(s, i);
    return s;
}

} // namespace

TEST_CASE("rootEndFromName: first, last, auto; anything else named with the choices", "[io][roots]")
{
    for (RootEnd e : {RootEnd::First, RootEnd::Last, RootEnd::Auto}) REQUIRE(rootEndFromName(rootEndName(e)) == e);
    REQUIRE_THROWS_AS(rootEndFromName("tip"), ValueError);
    REQUIRE_THROWS_WITH(rootEndFromName("tip"), Contains("roots='tip': must be first, last or auto"));
}

TEST_CASE("orientStrandRoots: last reverses every strand with its per-vertex attributes", "[io][roots]")
{
    const StrandSet s = test::sampleStrands(true);
    StrandSet r = s;
    const RootEndDecision d = orientStrandRoots(r, RootEnd::Last);
    REQUIRE(d.reversed);
    REQUIRE(r.offsets == s.offsets);
    for (std::size_t i = 0; i < s.numStrands(); ++i) {
        const std::size_t b = s.offsets[i], e = s.offsets[i + 1];
        for (std::size_t k = 0; k < e - b; ++k) {
            REQUIRE(r.positions[b + k] == s.positions[e - 1 - k]);
            REQUIRE(r.thickness[b + k] == s.thickness[e - 1 - k]);
            REQUIRE(r.transparency[b + k] == s.transparency[e - 1 - k]);
            REQUIRE(r.color[b + k] == s.color[e - 1 - k]);
        }
    }
    StrandSet f = s;
    REQUIRE_FALSE(orientStrandRoots(f, RootEnd::First).reversed);
    REQUIRE(f.positions == s.positions);
}

TEST_CASE("orientStrandRoots: auto without a head keeps hair rooted first and turns hair stored tip first, at any scale", "[io][roots]")
{
    for (float scale : {0.01f, 1.f, 100.f}) {
        for (unsigned seed : {1u, 2u, 3u}) {
            CAPTURE(scale, seed);
            const StrandSet hair = hairOnSphere(200, Vec3f(0.3f, 1.7f, -0.2f) * scale, 0.1f * scale, seed);
            StrandSet kept = hair;
            const RootEndDecision k = orientStrandRoots(kept, RootEnd::Auto);
            CAPTURE(k.scoreFirst, k.scoreLast);
            REQUIRE(k.decided);
            REQUIRE_FALSE(k.reversed);
            REQUIRE(kept.positions == hair.positions);
            REQUIRE(describeRootEndDecision(k).empty());

            StrandSet turned = reversed(hair);
            const RootEndDecision t = orientStrandRoots(turned, RootEnd::Auto);
            REQUIRE(t.reversed);
            REQUIRE(turned.positions == hair.positions);
            REQUIRE_THAT(describeRootEndDecision(t), Contains("reversed 100 % of the strands (200 of 200)"));
        }
    }
}

TEST_CASE("orientStrandRoots: auto with a head takes the end nearer it in most strands", "[io][roots]")
{
    const Vec3f c(0.f, 1.7f, 0.f);
    const float r = 0.1f;
    const SurfaceDistanceFn head = [&](const Vec3f& p) { return std::abs(double((p - c).length() - r)); };
    // Few strands are enough with a head.
    const StrandSet hair = hairOnSphere(5, c, r, 7);
    StrandSet kept = hair;
    const RootEndDecision k = orientStrandRoots(kept, RootEnd::Auto, head);
    REQUIRE(k.usedHead);
    REQUIRE(k.scoreFirst == Approx(1.0));
    REQUIRE_FALSE(k.reversed);
    StrandSet turned = reversed(hair);
    const RootEndDecision t = orientStrandRoots(turned, RootEnd::Auto, head);
    REQUIRE(t.reversed);
    REQUIRE(turned.positions == hair.positions);
    REQUIRE_THAT(describeRootEndDecision(t), Contains("nearer the head in 100 % of the strands"));
}

TEST_CASE("orientStrandRoots: auto without a head leaves fewer than 32 strands as stored, and says so", "[io][roots]")
{
    const StrandSet hair = reversed(hairOnSphere(kAutoRootsMinStrands - 1, Vec3f(0.f), 1.f, 4));
    StrandSet s = hair;
    const RootEndDecision d = orientStrandRoots(s, RootEnd::Auto);
    REQUIRE_FALSE(d.decided);
    REQUIRE_FALSE(d.reversed);
    REQUIRE(s.positions == hair.positions);
    REQUIRE_THAT(describeRootEndDecision(d), Contains("31 strand(s) are too few to tell the root end without a head (32 needed)"));
}

TEST_CASE("readStrands: ReadOptions::roots is applied after any reader, with the warning in the report", "[io][roots]")
{
    const StrandSet hair = hairOnSphere(100, Vec3f(0.f), 10.f, 5);
    const std::string tipFirst = test::tempPath("tip_first.hair");
    writeHair(tipFirst, reversed(hair));
    ReadOptions opts;
    opts.roots = RootEnd::Auto;
    ReadReport report;
    const StrandSet r = readStrands(tipFirst, opts, &report);
    test::requireSameStrands(hair, r);
    REQUIRE(report.warnings.size() == 1);
    REQUIRE_THAT(report.warnings[0], Contains("tip_first.hair: roots=auto reversed 100 % of the strands (100 of 100)"));

    opts.roots = RootEnd::Last;
    ReadReport quiet;
    test::requireSameStrands(hair, readStrands(tipFirst, opts, &quiet));
    REQUIRE(quiet.warnings.empty());
    // A .obj goes through the same place.
    const std::string obj = test::tempPath("tip_first.obj");
    writeStrands(obj, reversed(hair));
    test::requireSameStrands(hair, readStrands(obj, opts), 1e-5f);
}

namespace {
/// Every shared hairstyle (SOURCES.md), by its path under hair/.
std::vector<std::string> sharedHairstyles()
{
    std::vector<std::string> out;
    const std::filesystem::path root = test::sharedData() + "/hair";
    for (const auto& e : std::filesystem::recursive_directory_iterator(root)) {
        const std::string ext = e.path().extension().string();
        if (e.is_regular_file() && isStrandFile(e.path().string()) && ext != ".md") out.push_back(e.path().string());
    }
    std::sort(out.begin(), out.end());
    return out;
}
} // namespace

TEST_CASE("orientStrandRoots: auto turns none of the shared hairstyles and every one of them reversed", "[io][roots][data]")
{
    VDBHAIR_REQUIRE_SHARED_DATA();
    std::size_t decided = 0, undecided = 0;
    for (const std::string& path : sharedHairstyles()) {
        CAPTURE(path);
        ReadReport quiet;
        const StrandSet hair = readStrands(path, {}, &quiet);
        StrandSet kept = hair;
        const RootEndDecision k = orientStrandRoots(kept, RootEnd::Auto);
        CAPTURE(hair.numStrands(), k.scoreFirst, k.scoreLast);
        REQUIRE_FALSE(k.reversed);
        StrandSet turned = reversed(hair);
        const RootEndDecision t = orientStrandRoots(turned, RootEnd::Auto);
        if (hair.numStrands() < kAutoRootsMinStrands) {
            // HairNet's 5 guide strands a style: too few to tell; kept as stored either way.
            REQUIRE_FALSE(t.decided);
            ++undecided;
            continue;
        }
        REQUIRE(t.reversed);
        REQUIRE(turned.positions == hair.positions);
        ++decided;
    }
    REQUIRE(decided >= 21);
    CAPTURE(undecided);
}

TEST_CASE("orientStrandRoots: auto with each shared head turns none of its hairstyles and every one reversed", "[io][roots][data]")
{
    VDBHAIR_REQUIRE_SHARED_DATA();
    const std::string hair = test::sharedData() + "/hair/", scalp = test::sharedData() + "/scalp/";
    const std::vector<std::pair<std::string, std::string>> pairs = {
        {"cyhair/Bangs_100.hair", "ct2hair/Bangs_head.ply"},
        {"cyhair/straight.hair", "cem_yuksel/woman_head.ply"},
        {"hairnet_convdata/strands00014_00035_00010.convdata", "usc_hairsalon/head_model.ply"},
        {"tressfx/ascii_v2/hair_free_16_guide.tfx", "tressfx/head_max4.obj"},
        {"tressfx/ascii_v2/hair_front_16_guide.tfx", "tressfx/head_max4.obj"},
        {"tressfx/ascii_v2/hair_pulled_16_guide.tfx", "tressfx/head_max4.obj"},
        {"tressfx/ascii_v2/hair_tail_16_guide.tfx", "tressfx/head_max4.obj"},
        {"tressfx/ascii_v2/ruby_long_hair_16_guide.tfx", "tressfx/ruby_head.obj"},
        {"tressfx/ascii_v2/ruby_short_hair_16_guide.tfx", "tressfx/ruby_head.obj"},
        {"tressfx/binary_v4/GEO-sintel_hair_emit.001-sintel_hair.tfx", "sintel/sintel.obj"},
    };
    for (const auto& [h, m] : pairs) {
        CAPTURE(h, m);
        // The distance to the mesh's nearest vertex, as `--head MESH` measures it.
        auto pts = std::make_shared<std::vector<Vec3d>>();
        for (const Vec3f& v : readTriangleMesh(scalp + m).vertices) pts->emplace_back(v.x(), v.y(), v.z());
        auto cloud = std::make_shared<PointCloud>(PointCloud{pts.get()});
        auto tree = std::make_shared<PointKdTree>(3, *cloud, nanoflann::KDTreeSingleIndexAdaptorParams(10));
        tree->buildIndex();
        const SurfaceDistanceFn head = [pts, cloud, tree](const Vec3f& p) {
            const double q[3] = {p.x(), p.y(), p.z()};
            std::uint32_t index = 0;
            double d2 = 0.0;
            tree->knnSearch(q, 1, &index, &d2);
            return std::sqrt(d2);
        };
        ReadReport quiet;
        const StrandSet s = readStrands(hair + h, {}, &quiet);
        StrandSet kept = s;
        const RootEndDecision k = orientStrandRoots(kept, RootEnd::Auto, head);
        CAPTURE(k.scoreFirst, k.scoreLast);
        REQUIRE_FALSE(k.reversed);
        StrandSet turned = reversed(s);
        REQUIRE(orientStrandRoots(turned, RootEnd::Auto, head).reversed);
        REQUIRE(turned.positions == s.positions);
    }
}
