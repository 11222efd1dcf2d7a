#include "../TestUtil.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/io/ObjFile.h>

using namespace vdbhair;
using Catch::Matchers::Contains;

TEST_CASE("readObj/writeObj: positions and colours round-trip exactly", "[io]")
{
    StrandSet s = test::sampleStrands(true);
    s.thickness.clear();
    s.transparency.clear();
    const std::string path = test::tempPath("rt.obj");
    writeObj(path, s);
    const StrandSet r = readObj(path);
    test::requireSameStrands(s, r);
    REQUIRE(r.color == s.color);
}

TEST_CASE("readObj: Houdini polylines, Blender edge chains, negative indices, faces ignored", "[io]")
{
    const std::string text =
        "# polylines\n"
        "o hair\n"
        "v 0 0 0\nv 1 0 0\nv 2 0 0\n"
        "l 1 2 3\n"                       // Houdini: one element per curve
        "v 0 1 0\nv 1 1 0\nv 2 1 0\nv 3 1 0\n"
        "l 4 5\nl 5 6\nl 6 7\n"           // Blender: chained edges form one strand
        "v 0 2 0\nv 1 2 0\n"
        "l -2 -1\n"                       // negative: relative to the latest vertex
        "f 1 2 3\n"
        "vn 0 0 1\n";
    ReadReport report;
    const StrandSet s = readObj(test::writeBytes("mixed.obj", text), {}, &report);
    REQUIRE(s.numStrands() == 3);
    REQUIRE(s.size(0) == 3);
    REQUIRE(s.size(1) == 4);
    REQUIRE(s.positions[s.begin(1) + 3] == Vec3f(3.f, 1.f, 0.f));
    REQUIRE(s.size(2) == 2);
    REQUIRE(s.root(2) == Vec3f(0.f, 2.f, 0.f));
    REQUIRE(s.color.empty());
    REQUIRE(report.warnings.size() == 1);  // o, f and vn lines, counted in one warning
    REQUIRE_THAT(report.warnings[0], Contains("lines other than v and l"));
}

TEST_CASE("readObj: each kind of bad input has its own error", "[io]")
{
    REQUIRE_THROWS_WITH(readObj(test::writeBytes("e1.obj", "v 0 0 0\nv 1 0 0\nl 1 3\n")),
                        Contains("line 3: vertex index 3 is out of range: 2 vertices are defined so far"));
    REQUIRE_THROWS_WITH(readObj(test::writeBytes("e2.obj", "v 0 0 0\nl 0 1\n")), Contains("vertex index 0 is out of range"));
    REQUIRE_THROWS_WITH(readObj(test::writeBytes("e3.obj", "v 0 x1 0\n")), Contains("line 1: 'x1' is not a valid number (y)"));
    REQUIRE_THROWS_WITH(readObj(test::writeBytes("e4.obj", "v 0 0\n")), Contains("line 1: a 'v' line needs 3 coordinates, got 2"));
    REQUIRE_THROWS_WITH(readObj(test::writeBytes("e5.obj", "v 0 0 0\nv 1 1 1\nf 1 2 1\n")), Contains("no polylines"));
    REQUIRE_THROWS_WITH(readObj(test::writeBytes("e6.obj", "v 0 nan 0\nv 0 0 0\nl 1 2\n")), Contains("line 1: vertex 0 has a non-finite coordinate"));
    ReadOptions strict;
    strict.shortStrands = ShortStrandPolicy::Reject;
    REQUIRE_THROWS_WITH(readObj(test::writeBytes("e7.obj", "v 0 0 0\nl 1\n"), strict), Contains("line 2: strand 0 has 1 vertices"));
}
