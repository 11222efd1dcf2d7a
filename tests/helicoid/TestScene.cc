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
