#include "../TestUtil.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/io/ObjFile.h>

#include <algorithm>
#include <random>
#include <sstream>

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

TEST_CASE("writeObj: Blender's form by default, one two-vertex 'l' per segment; polylines on request", "[io]")
{
    const StrandSet s = test::sampleStrands(false);
    const std::string path = test::tempPath("edges.obj");
    writeObj(path, s);
    const std::string text = test::readBytes(path);
    std::size_t lines = 0, vLines = 0;
    std::istringstream in(text);
    for (std::string line; std::getline(in, line);) {
        if (line.rfind("l ", 0) == 0) {
            ++lines;
            std::istringstream l(line.substr(2));
            std::size_t a = 0, b = 0, extra = 0;
            REQUIRE(bool(l >> a >> b));
            REQUIRE(b == a + 1);  // chained, root to tip
            REQUIRE_FALSE(bool(l >> extra));  // exactly two vertices: Blender 3.4 keeps only the first segment of more
        }
        if (line.rfind("v ", 0) == 0) ++vLines;
    }
    REQUIRE(vLines == s.numVertices());
    REQUIRE(lines == s.numVertices() - s.numStrands());
    test::requireSameStrands(s, readObj(path));

    writeObj(path, s, ObjLineStyle::Polylines);
    const std::string poly = test::readBytes(path);
    REQUIRE(std::count(poly.begin(), poly.end(), 'l') >= s.numStrands());
    test::requireSameStrands(s, readObj(path));
    REQUIRE(objLineStyleFromName("polylines") == ObjLineStyle::Polylines);
    REQUIRE_THROWS_WITH(objLineStyleFromName("curves"), Contains("'curves' is not one of edges"));
}

TEST_CASE("readObj: strands rebuilt from edges in any order and direction", "[io]")
{
    const StrandSet s = test::sampleStrands(false);
    // Every segment as an edge, shuffled, each listed in a random direction (as Blender exports).
    std::vector<std::pair<std::size_t, std::size_t>> edges;
    for (std::size_t i = 0; i < s.numStrands(); ++i)
        for (std::size_t v = s.begin(i); v + 1 < s.end(i); ++v) edges.push_back({v + 1, v + 2});
    std::mt19937 rng(17);
    for (int trial = 0; trial < 5; ++trial) {
        std::shuffle(edges.begin(), edges.end(), rng);
        std::ostringstream text;
        text.precision(9);
        for (const Vec3f& p : s.positions) text << "v " << p.x() << ' ' << p.y() << ' ' << p.z() << '\n';
        for (const auto& [a, b] : edges) {
            if (rng() % 2) text << "l " << a << ' ' << b << '\n';
            else text << "l " << b << ' ' << a << '\n';
        }
        CAPTURE(trial);
        test::requireSameStrands(s, readObj(test::writeBytes("shuffled.obj", text.str())));
    }
}

TEST_CASE("readObj: roots at the lower-index end, or nearest a given point", "[io]")
{
    // Written tip first: by default the lower index (the tip here) becomes the root.
    const std::string path = test::writeBytes("reversed.obj", "v 0 5 0\nv 0 4 0\nv 0 3 0\nl 3 2\nl 2 1\n");
    StrandSet s = readObj(path);
    REQUIRE(s.numStrands() == 1);
    REQUIRE(s.root(0) == Vec3f(0.f, 5.f, 0.f));
    ReadOptions opts;
    opts.objRootNear = Vec3f(0.f, 0.f, 0.f);  // e.g. the head's centre
    s = readObj(path, opts);
    REQUIRE(s.root(0) == Vec3f(0.f, 3.f, 0.f));
    REQUIRE(s.tip(0) == Vec3f(0.f, 5.f, 0.f));
}

TEST_CASE("readObj: a branching vertex and a closed loop are errors naming the vertex", "[io]")
{
    REQUIRE_THROWS_WITH(readObj(test::writeBytes("branch.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 3 0 0\nl 1 2\nl 2 3\nl 2 4\n")),
                        Contains("vertex 2 joins 3 or more others (edges on lines 5, 6 and 7); a strand cannot branch"));
    REQUIRE_THROWS_WITH(readObj(test::writeBytes("loop.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 9 9 9\nv 9 8 9\nl 1 2 3 1\nl 4 5\n")),
                        Contains("vertex 1 lies on a closed loop of edges (line 6)"));
    // The same edge twice is one edge (with a warning), not a branch.
    ReadReport report;
    const StrandSet s = readObj(test::writeBytes("twice.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nl 1 2\nl 2 3\nl 3 2\n"), {}, &report);
    REQUIRE(s.numStrands() == 1);
    REQUIRE(s.size(0) == 3);
    REQUIRE(report.warnings.size() == 1);
    REQUIRE_THAT(report.warnings[0], Contains("ignored 1 repeated edge(s)"));
}
