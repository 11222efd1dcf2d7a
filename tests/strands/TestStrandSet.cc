#include "../TestUtil.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/strands/StrandSet.h>

using namespace vdbhair;
using Catch::Matchers::Contains;

TEST_CASE("StrandSet: offsets are prefix sums of the strands added", "[strands]")
{
    StrandSet s;
    REQUIRE(s.empty());
    s.addStrand(test::helix(1, 0.2, 3, 5));
    s.addStrand(test::helix(1, 0.2, 3, 3));
    REQUIRE(s.numStrands() == 2);
    REQUIRE(s.numVertices() == 8);
    REQUIRE(s.offsets == std::vector<std::uint32_t>{0, 5, 8});
    REQUIRE(s.size(1) == 3);
    REQUIRE(s.root(1) == s.positions[5]);
    REQUIRE(s.tip(0) == s.positions[4]);
    REQUIRE_NOTHROW(s.validate("test"));
}

TEST_CASE("StrandSet: validate names the first broken rule", "[strands]")
{
    StrandSet s = test::sampleStrands();
    REQUIRE_NOTHROW(s.validate("here"));

    SECTION("a strand of one vertex")
    {
        s.addStrand(std::vector<Vec3f>{Vec3f(0.f)});
        REQUIRE_THROWS_WITH(s.validate("here"), Contains("here: strand 3 has 1 vertices"));
    }
    SECTION("a NaN coordinate")
    {
        s.positions[4].y() = std::nanf("");
        REQUIRE_THROWS_AS(s.validate("here"), FormatError);
        REQUIRE_THROWS_WITH(s.validate("here"), Contains("vertex 4 has a non-finite coordinate"));
    }
    SECTION("an attribute of the wrong size")
    {
        s.thickness.pop_back();
        REQUIRE_THROWS_WITH(s.validate("here"), Contains("thickness has"));
    }
}

TEST_CASE("StrandSet: append keeps attributes, filling defaults for the side without them", "[strands]")
{
    StrandSet a = test::sampleStrands(true);
    const StrandSet b = test::sampleStrands(false);
    const std::size_t nV = a.numVertices();
    a.append(b);
    REQUIRE(a.numStrands() == 6);
    REQUIRE(a.numVertices() == 2 * nV);
    REQUIRE(a.thickness.size() == 2 * nV);
    REQUIRE(a.thickness[nV] == a.defaults.thickness);
    REQUIRE(a.positions[nV] == b.positions[0]);
    REQUIRE(a.offsets.back() == 2 * nV);
    REQUIRE_NOTHROW(a.validate("append"));

    StrandSet c = test::sampleStrands(false);
    c.append(test::sampleStrands(true));
    REQUIRE(c.color.size() == c.numVertices());
    REQUIRE(c.color[0] == c.defaults.color);
    REQUIRE_NOTHROW(c.validate("append"));

    // Into an empty set, a temporary's storage is taken: the same set as a copying append gives.
    StrandSet withIds = test::sampleStrands(true);
    withIds.strandId = {7, 8, 9};
    withIds.rootUV = {Vec2f(0.1f, 0.2f), Vec2f(0.3f, 0.4f), Vec2f(0.5f, 0.6f)};
    withIds.defaults.thickness = 0.25f;
    StrandSet copied, moved;
    copied.append(withIds);
    const Vec3f* storage = withIds.positions.data();
    moved.append(std::move(withIds));
    REQUIRE(moved.positions.data() == storage);
    for (const StrandSet* x : {&copied, &moved}) REQUIRE(x->defaults.thickness == 0.25f);
    REQUIRE(moved.positions == copied.positions);
    REQUIRE(moved.offsets == copied.offsets);
    REQUIRE(moved.thickness == copied.thickness);
    REQUIRE(moved.transparency == copied.transparency);
    REQUIRE(moved.color == copied.color);
    REQUIRE(moved.rootUV == copied.rootUV);
    REQUIRE(moved.strandId == copied.strandId);
    // Into a set that has strands, a temporary is appended as any other set.
    StrandSet d = test::sampleStrands(false);
    d.append(test::sampleStrands(true));
    REQUIRE(d.positions == c.positions);
    REQUIRE(d.color == c.color);
}

TEST_CASE("StrandSet: selectStrands and scaleStrands", "[strands]")
{
    const StrandSet s = test::sampleStrands();
    const StrandSet sel = selectStrands(s, {1, 0, 1});
    REQUIRE(sel.numStrands() == 2);
    REQUIRE(sel.numVertices() == s.size(0) + s.size(2));
    REQUIRE(sel.positions[s.size(0)] == s.root(2));
    REQUIRE(sel.color[s.size(0)] == s.color[s.begin(2)]);
    REQUIRE_NOTHROW(sel.validate("select"));

    StrandSet t = s;
    scaleStrands(t, -2.f);
    REQUIRE(t.positions[3] == s.positions[3] * -2.f);
    REQUIRE(t.thickness[3] == Approx(s.thickness[3] * 2.f));

    const BBox box = computeBBox(s);
    for (const Vec3f& p : s.positions) {
        for (int k = 0; k < 3; ++k) {
            REQUIRE(p[k] >= box.min[k]);
            REQUIRE(p[k] <= box.max[k]);
        }
    }
}
