#include "../TestUtil.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/helicoid/Scene.h>
#include <vdbhair/strands/Measures.h>

#include <tbb/global_control.h>

using namespace vdbhair;
using Catch::Matchers::Contains;

namespace {
const char* kScene = R"({"vdbhair": "scene/1", "seed": 7, "step": 0.01,
 "guides": [
  {"root": [0,0,0], "frame": {"tangent": [1,0,0], "normal": [0,1,0]},
   "pieces": [{"k": [1.0, -0.1, 0.3, 1.0], "length": 2.0, "roll": 0.0}],
   "waviness": {"amplitude": 0.02, "frequency": 40.0},
   "wisp": {"count": 256, "radius": 0.05, "fanning": 0.1}},
  {"root": [1,0,0], "frame": {"tangent": [0,0,1], "normal": [0,1,0]},
   "pieces": [{"k": [0.5, 0, 0, 0], "length": 1.0}, {"k": [0, 0, 2.0, 0.3], "length": 0.5, "roll": 1.0}],
   "fit": {"frechet": 0.01}}]})";

Scene parse(const std::string& text) { return sceneFromJson(nlohmann::json::parse(text), "s.json"); }
} // namespace

TEST_CASE("growScene: each guide, then its wisps, every strand of its guide's length", "[helicoid]")
{
    const Scene s = parse(kScene);
    const StrandSet strands = growScene(s);
    REQUIRE(strands.numStrands() == 1 + 256 + 1);
    REQUIRE(strands.size(0) == 201);
    REQUIRE(strands.size(257) == 151);
    // Eq. 4 at the root: a·E_B, with E_B = tangent x normal = +z.
    REQUIRE((strands.root(0) - Vec3f(0.f, 0.f, 0.02f)).length() < 1e-7f);
    REQUIRE(strands.root(257) == Vec3f(1.f, 0.f, 0.f));
    REQUIRE_NOTHROW(strands.validate("grow"));
}

TEST_CASE("growScene: bitwise identical with 1 and 2 threads", "[helicoid]")
{
    const Scene s = parse(kScene);
    StrandSet one, two;
    {
        tbb::global_control c(tbb::global_control::max_allowed_parallelism, 1);
        one = growScene(s);
    }
    {
        tbb::global_control c(tbb::global_control::max_allowed_parallelism, 2);
        two = growScene(s);
    }
    REQUIRE(one.offsets == two.offsets);
    REQUIRE(std::memcmp(one.positions.data(), two.positions.data(), one.positions.size() * sizeof(Vec3f)) == 0);
    // And the seed matters.
    Scene other = s;
    other.seed = 8;
    const StrandSet three = growScene(other);
    REQUIRE(std::memcmp(one.positions.data(), three.positions.data(), one.positions.size() * sizeof(Vec3f)) != 0);
}

TEST_CASE("sceneToJson / sceneFromJson round-trip, and writeScene / readScene", "[helicoid]")
{
    const Scene s = parse(kScene);
    const Scene r = sceneFromJson(sceneToJson(s), "r");
    REQUIRE(r.guides.size() == 2);
    REQUIRE(r.guides[1].pieces[1].roll == 1.0);
    REQUIRE(r.guides[1].fit["frechet"] == 0.01);
    REQUIRE(r.guides[0].wisp->count == 256);
    const std::string path = test::tempPath("scene.json");
    writeScene(path, s);
    const StrandSet a = growScene(s), b = growScene(readScene(path));
    REQUIRE(std::memcmp(a.positions.data(), b.positions.data(), a.positions.size() * sizeof(Vec3f)) == 0);
}

TEST_CASE("sceneFromJson: errors name the key path and the rule", "[helicoid]")
{
    auto bad = [](const std::string& from, const std::string& to) {
        std::string text = kScene;
        const std::size_t at = text.find(from);
        REQUIRE(at != std::string::npos);
        return text.replace(at, from.size(), to);
    };
    REQUIRE_THROWS_WITH(parse(bad("\"k\": [0.5, 0, 0, 0]", "\"k\": [0.5, 0, 0]")), Contains("s.json: guides[1].pieces[0].k: expected 4 numbers"));
    REQUIRE_THROWS_WITH(parse(bad("\"radius\"", "\"radiuss\"")), Contains("guides[0].wisp.radiuss: unknown key"));
    REQUIRE_THROWS_WITH(parse(bad("\"scene/1\"", "\"scene/2\"")), Contains("vdbhair: expected \"scene/1\""));
    REQUIRE_THROWS_WITH(parse(bad("\"step\": 0.01", "\"step\": -1")), Contains("step: must be positive"));
    REQUIRE_THROWS_WITH(parse(bad("\"normal\": [0,1,0]}", "\"normal\": [2,0,0]}")), Contains("guides[0].frame: frame normal must not be parallel"));
    REQUIRE_THROWS_WITH(parse(bad("\"length\": 2.0", "\"length\": \"2\"")), Contains("guides[0].pieces[0].length: expected a number, got string"));
    REQUIRE_THROWS_WITH(parse(bad("\"count\": 256", "\"count\": -3")), Contains("guides[0].wisp.count: expected a non-negative integer"));
    REQUIRE_THROWS_WITH(parse(bad("\"length\": 2.0", "\"length\": 0")), Contains("guides[0].pieces: the pieces' lengths add up to 0"));
    REQUIRE_THROWS_AS(readScene(test::writeBytes("broken.json", "{\"vdbhair\": ")), FormatError);
    // A scene too large for the cap is refused before anything is grown.
    GrowOptions small;
    small.maxVertices = 1000;
    REQUIRE_THROWS_AS(growScene(parse(kScene), small), LimitError);
}

namespace {
/// One guide on a sphere scalp of radius R about the origin, rooted at @a u·R, its tangent along
/// the sphere lifted by @a lift radians, a wisp with the scalp normal u at its root.
std::string sphereScene(const Vec3d& u, double R, double lift, const std::string& wispExtra)
{
    const Vec3d d = (std::abs(u.y()) < 0.9 ? Vec3d(0, 1, 0) : Vec3d(1, 0, 0)).cross(u).unit();
    const Vec3d t = (std::cos(lift) * d + std::sin(lift) * u).unit();
    auto vec = [](const Vec3d& v) {
        return "[" + std::to_string(v.x()) + "," + std::to_string(v.y()) + "," + std::to_string(v.z()) + "]";
    };
    return R"({"vdbhair": "scene/1", "seed": 3, "step": 0.05, "head": {"sphere": [0, 0, 0, )" + std::to_string(R) + R"(]},
 "guides": [{"root": )" + vec(R * u) + R"(, "frame": {"tangent": )" + vec(t) + R"(, "normal": )" + vec(-u) + R"(},
   "pieces": [{"k": [0.1, 0, 0.02, 0], "length": 3.0}],
   "wisp": {"count": 400, "radius": 0.9, "fanning": 0.0, "normal": )" + vec(u) + wispExtra + "}}]}";
}
} // namespace

TEST_CASE("growScene: a wisp with the scalp normal has its roots in the scalp's tangent plane", "[helicoid]")
{
    for (const Vec3d& dir : {Vec3d(0, 1, 0), Vec3d(0.3, 0.8, -0.5), Vec3d(-1, -0.2, 0.1)}) {
        const Vec3d u = dir.unit();
        for (double lift : {0.0, 0.12, 0.5}) {
            const double R = 10.0;
            const Scene s = parse(sphereScene(u, R, lift, ""));
            REQUIRE(s.head);
            REQUIRE(s.head->radius == 10.0);
            const StrandSet strands = growScene(s);
            REQUIRE(strands.numStrands() == 401);
            const Vec3d root = R * u;
            double maxPlane = 0.0, maxRadius = 0.0;
            std::size_t inside = 0;
            for (std::size_t i = 1; i < strands.numStrands(); ++i) {
                const Vec3d p(strands.root(i));
                maxPlane = std::max(maxPlane, std::abs((p - root).dot(u)));
                maxRadius = std::max(maxRadius, (p - root).length());
                // Below the sphere by more than float rounding: inside the head.
                inside += p.length() < R - 1e-5 * R;
            }
            CAPTURE(u, lift, maxPlane, maxRadius);
            CHECK(maxPlane < 1e-4 * R);
            CHECK(inside == 0);
            CHECK(maxRadius <= 0.9 + 1e-5);
            CHECK(maxRadius > 0.8);  // the disk is filled, not collapsed onto a line
        }
    }
    // Without the normal (the old rule) the disk is perpendicular to the guide's tangent, so a
    // guide lying along the scalp has wisp roots inside the head.
    std::string text = sphereScene(Vec3d(0, 1, 0), 10.0, 0.0, "");
    text.replace(text.find(", \"normal\": [0.000000,1.000000,0.000000]"), std::string(", \"normal\": [0.000000,1.000000,0.000000]").size(), "");
    const StrandSet old = growScene(parse(text));
    std::size_t inside = 0;
    for (std::size_t i = 1; i < old.numStrands(); ++i) inside += Vec3d(old.root(i)).length() < 10.0 - 1e-3;
    CHECK(inside > 100);
}

TEST_CASE("growScene: strays are the asked share of a wisp, turned well beyond its fanning", "[helicoid]")
{
    // A straight guide along +x: every wisp strand is straight, its direction its rotation.
    auto scene = [](const std::string& wisp) {
        return R"({"vdbhair": "scene/1", "seed": 5, "step": 0.1,
 "guides": [{"root": [0,0,0], "frame": {"tangent": [1,0,0], "normal": [0,1,0]},
   "pieces": [{"k": [0, 0, 0, 0], "length": 1.0}], "wisp": {"count": 4000, "radius": 0.05, "fanning": 0.05)" + wisp + "}}]}";
    };
    for (const std::string& normal : {std::string(), std::string(", \"normal\": [0,1,0]")}) {
        const double F = 0.2;
        const StrandSet strands = growScene(parse(scene(normal + ", \"strays\": 0.2")));
        std::size_t strays = 0, between = 0;
        for (std::size_t i = 1; i < strands.numStrands(); ++i) {
            const Vec3d dir = (Vec3d(strands.positions[strands.offsets[i + 1] - 1]) - Vec3d(strands.root(i))).unit();
            const double angle = std::acos(std::min(1.0, dir.x()));
            // Fanning turns a strand by at most 0.05 rad; a stray by 0.3-0.6 rad more.
            if (angle > 0.15) ++strays;
            if (angle > 0.05 + 1e-4 && angle < 0.25 - 1e-4) ++between;
            if (angle > 0.65 + 1e-4) FAIL("a strand turned by " << angle << " rad");
            if (!normal.empty() && angle > 0.15) {
                // With a normal, strays turn about it: sideways, within the scalp's tangent plane
                // (up to the fanning).
                CHECK(std::abs(dir.y()) < std::sin(0.05) + 1e-4);
            }
        }
        // Binomial: mean n F, standard deviation sqrt(n F (1 - F)) = 25.3; 5 deviations.
        const double n = 4000.0, sd = std::sqrt(n * F * (1.0 - F));
        CAPTURE(normal, strays);
        CHECK(std::abs(double(strays) - n * F) < 5.0 * sd);
        CHECK(between == 0);
    }
    // strays 0 grows exactly what a wisp without the key grows; strays 1 makes every strand one.
    const StrandSet none = growScene(parse(scene(""))), zero = growScene(parse(scene(", \"strays\": 0")));
    REQUIRE(std::memcmp(none.positions.data(), zero.positions.data(), none.positions.size() * sizeof(Vec3f)) == 0);
    const StrandSet all = growScene(parse(scene(", \"strays\": 1")));
    for (std::size_t i = 1; i < all.numStrands(); ++i) {
        const Vec3d dir = (Vec3d(all.positions[all.offsets[i + 1] - 1]) - Vec3d(all.root(i))).unit();
        REQUIRE(std::acos(std::min(1.0, dir.x())) > 0.25 - 1e-4);
    }
}

TEST_CASE("growScene: wisp normals and strays are bitwise identical with 1 and 2 threads, and round-trip", "[helicoid]")
{
    const Scene s = parse(sphereScene(Vec3d(0.3, 0.8, -0.5).unit(), 10.0, 0.12, ", \"strays\": 0.1, \"fanning\": 0.02"));
    StrandSet one, two;
    {
        tbb::global_control c(tbb::global_control::max_allowed_parallelism, 1);
        one = growScene(s);
    }
    {
        tbb::global_control c(tbb::global_control::max_allowed_parallelism, 2);
        two = growScene(s);
    }
    REQUIRE(std::memcmp(one.positions.data(), two.positions.data(), one.positions.size() * sizeof(Vec3f)) == 0);
    const std::string path = test::tempPath("scene-head.json");
    writeScene(path, s);
    const Scene r = readScene(path);
    REQUIRE(r.head);
    REQUIRE(r.head->radius == 10.0);
    REQUIRE(r.guides[0].wisp->strays == 0.1);
    REQUIRE((r.guides[0].wisp->normal - s.guides[0].wisp->normal).length() < 1e-12);
    const StrandSet back = growScene(r);
    REQUIRE(std::memcmp(one.positions.data(), back.positions.data(), one.positions.size() * sizeof(Vec3f)) == 0);
}

TEST_CASE("sceneFromJson: head, wisp normal and strays errors name the key path", "[helicoid]")
{
    const std::string text = sphereScene(Vec3d(0, 1, 0), 10.0, 0.0, ", \"strays\": 0.1");
    auto bad = [&](const std::string& from, const std::string& to) {
        std::string t = text;
        const std::size_t at = t.find(from);
        REQUIRE(at != std::string::npos);
        return t.replace(at, from.size(), to);
    };
    REQUIRE_NOTHROW(parse(text));
    REQUIRE_THROWS_WITH(parse(bad("\"normal\": [0.000000,1.000000,0.000000]", "\"normal\": [0,0,0]")),
                        Contains("s.json: guides[0].wisp.normal: must be a non-zero vector"));
    REQUIRE_THROWS_WITH(parse(bad("\"normal\": [0.000000,1.000000,0.000000]", "\"normal\": [0,1]")),
                        Contains("guides[0].wisp.normal: expected 3 numbers"));
    REQUIRE_THROWS_WITH(parse(bad("\"strays\": 0.1", "\"strays\": 1.5")), Contains("guides[0].wisp.strays: must be a fraction in [0, 1]"));
    REQUIRE_THROWS_WITH(parse(bad("\"strays\": 0.1", "\"strays\": -0.1")), Contains("guides[0].wisp.strays: must be a fraction in [0, 1]"));
    REQUIRE_THROWS_WITH(parse(bad("\"head\": {\"sphere\": [0, 0, 0, 10.000000]}", "\"head\": {\"sphere\": [0, 0, 0, 0]}")),
                        Contains("s.json: head.sphere[3]: the radius must be positive"));
    REQUIRE_THROWS_WITH(parse(bad("\"head\": {\"sphere\": [0, 0, 0, 10.000000]}", "\"head\": {\"sphere\": [0, 0, 10]}")),
                        Contains("head.sphere: expected 4 numbers"));
    REQUIRE_THROWS_WITH(parse(bad("\"head\": {\"sphere\"", "\"head\": {\"mesh\": 1, \"sphere\"")), Contains("head.mesh: unknown key"));
    REQUIRE_THROWS_WITH(parse(bad("\"head\": {\"sphere\": [0, 0, 0, 10.000000]}", "\"head\": {\"sphere\": [0, \"a\", 0, 1]}")),
                        Contains("head.sphere[1]: expected a number"));
}

TEST_CASE("readScene: nesting beyond the cap and numbers beyond a double name the key path (issue 22)", "[helicoid][fuzz]")
{
    // 200,000 levels overflowed the stack; now refused at kMaxSceneDepth + 1 before any json is built.
    const std::size_t depth = 200000;
    const std::string deep = "{\"vdbhair\": \"scene/1\", \"guides\": [{\"fit\": " + std::string(depth, '[') + std::string(depth, ']') + "}]}";
    REQUIRE_THROWS_WITH(readScene(test::writeBytes("deep.json", deep)),
                        Contains("deep.json: guides[0].fit[0][0][0]") && Contains("nested 65 levels deep; a scene nests at most 64 levels"));
    REQUIRE_THROWS_WITH(readScene(test::writeBytes("big.json", "{\"vdbhair\": \"scene/1\", \"guides\": [], \"seed\": 1e400}")),
                        Contains("big.json: seed: number 1e400 is beyond the range of a double"));
    REQUIRE_THROWS_WITH(readScene(test::writeBytes("bad.json", "{\"vdbhair\": \"scene/1\", \"guides\": [tru]}")),
                        Contains("bad.json: guides[0]: not valid JSON: parse error at line 1, column"));
}
