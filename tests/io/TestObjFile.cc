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

TEST_CASE("readObj: free-form curves (bspline, bezier, rat, cardinal) with negative indices, after the lines", "[io][curves]")
{
    // The cubic Bezier (0,0,0) (1,2,0) (3,2,0) (4,0,0) at u = i/4 by its Bernstein form.
    auto bezier = [](double t) {
        const double s = 1.0 - t;
        return Vec3f(float(3 * s * s * t * 1 + 3 * s * t * t * 3 + t * t * t * 4), float(3 * s * s * t * 2 + 3 * s * t * t * 2), 0.f);
    };
    const std::string text =
        "# a line strand, then curves\n"
        "v 9 9 9\nv 9 8 9\nl 1 2\n"
        "v 0 0 0\nv 1 2 0\nv 3 2 0\nv 4 0 0\n"
        "cstype bezier\ndeg 3\n"
        "curv 0.0 1.0 3 4 5 6\nend\n"              // positive indices
        "curv 0.0 1.0 -4 -3 -2 -1\nparm u 0 1\nend\n"  // the same curve, relative indices
        "v 1 0 0 1\nv 1 1 0 0.70710678118654752\nv 0 1 0\n"
        "cstype rat bezier\ndeg 2\n"
        "curv 0 1 -3 \\\n -2 -1\n"                  // a continued line
        "end\n"
        "cstype bspline\ndeg 1\n"
        "curv 0 1 3 4 5\nparm u 0 0 0.5 1 1\nend\n"   // degree 1: the control polygon itself
        "v 0 0 5\nv 1 1 5\nv 2 0 6\nv 3 1 6\n"
        "cstype cardinal\ndeg 3\ncurv 0 1 -4 -3 -2 -1\nend\n";
    ReadOptions opts;
    opts.curveSamples = 5;
    ReadReport report;
    const StrandSet s = readObj(test::writeBytes("curves.obj", text), opts, &report);
    REQUIRE(report.warnings.empty());
    REQUIRE(s.numStrands() == 6);
    REQUIRE(s.size(0) == 2);  // the line first
    REQUIRE(s.root(0) == Vec3f(9.f, 9.f, 9.f));
    for (std::size_t i : {1, 2}) {
        REQUIRE(s.size(i) == 5);
        for (std::size_t k = 0; k < 5; ++k) REQUIRE((s.positions[s.begin(i) + k] - bezier(double(k) / 4.0)).length() < 1e-6f);
    }
    for (std::size_t k = 0; k < 5; ++k) REQUIRE(s.positions[s.begin(3) + k].length() == Approx(1.f).margin(1e-6));  // the quarter circle
    REQUIRE(s.root(3) == Vec3f(1.f, 0.f, 0.f));
    REQUIRE(s.tip(3).y() == Approx(1.f));
    // Degree 1 over knots 0 0 0.5 1 1: control points at u = 0, 0.5, 1; samples at 0, 0.25, ...
    REQUIRE(s.positions[s.begin(4) + 1] == Vec3f(0.5f, 1.f, 0.f));
    REQUIRE(s.positions[s.begin(4) + 2] == Vec3f(1.f, 2.f, 0.f));
    REQUIRE(s.root(5) == Vec3f(1.f, 1.f, 5.f));  // cardinal: from the second control point
    REQUIRE(s.tip(5) == Vec3f(2.f, 0.f, 6.f));   // to the last but one

    // Automatic samples: more than the 4 control points, and root and tip on the end points.
    const StrandSet a = readObj(test::writeBytes("curves.obj", text));
    REQUIRE(a.numStrands() == 6);
    REQUIRE(a.size(1) > 4);
    REQUIRE(a.root(1) == Vec3f(0.f, 0.f, 0.f));
    REQUIRE((a.tip(1) - Vec3f(4.f, 0.f, 0.f)).length() < 1e-6f);
}

TEST_CASE("readObj: curves only; curv2 and surf skipped with a warning; taylor refused", "[io][curves]")
{
    const std::string curve = "v 0 0 0\nv 1 0 0\nv 2 1 0\nv 3 1 0\ncstype bspline\ndeg 3\ncurv 0 1 1 2 3 4\nparm u 0 0 0 0 1 1 1 1\nend\n";
    REQUIRE(readObj(test::writeBytes("c1.obj", curve)).numStrands() == 1);
    ReadReport report;
    const StrandSet s = readObj(test::writeBytes("c2.obj", curve + "vp 0 0\nvp 1 0\ncurv2 1 2\nparm u 0 1\nend\nsurf 0 1 0 1 1 2 3 4\nparm u 0 1\nparm v 0 1\nend\n"), {}, &report);
    REQUIRE(s.numStrands() == 1);
    REQUIRE(report.warnings.size() == 2);  // the vp lines; the curv2 and surf elements
    REQUIRE_THAT(report.warnings[1], Contains("skipped 2 curv2/surf element(s) (first on line 12)"));
    REQUIRE_THROWS_AS(readObj(test::writeBytes("c3.obj", "v 0 0 0\ncstype taylor\n")), UnsupportedError);
    REQUIRE_THROWS_WITH(readObj(test::writeBytes("c3.obj", "v 0 0 0\ncstype taylor\n")), Contains("line 2: cstype taylor is not supported (bspline, bezier and cardinal curves are"));
}

TEST_CASE("readObj: each kind of bad curve has its own error, at the curv line", "[io][curves]")
{
    const std::string v4 = "v 0 0 0\nv 1 0 0\nv 2 1 0\nv 3 1 0\n";
    auto fails = [&](const std::string& body, const std::string& message) {
        CAPTURE(body);
        REQUIRE_THROWS_WITH(readObj(test::writeBytes("bad_curve.obj", v4 + body)), Contains(message));
    };
    fails("cstype bspline\ndeg 3\ncurv 0 1 1 2 5\nend\n", "line 7: vertex index 5 is out of range: 4 vertices are defined so far");
    fails("cstype bspline\ndeg 3\ncurv 0 1 -5 -1\nend\n", "line 7: vertex index -5 is out of range");
    fails("cstype bspline\ndeg 3\ncurv 0 1 1 2 3\nend\n", "line 7: curve: degree 3 needs at least 4 control points, got 3");
    fails("cstype bspline\ndeg 3\ncurv 0 1 1 2 3 4\nparm u 0 0 0 1 0 1 1 1\nend\n", "line 7: curve: knot 5 (0) is below knot 4 (1)");
    fails("cstype bspline\ndeg 3\ncurv 0 1 1 2 3 4\nparm u 0 1\nend\n", "the knot vector (parm u) has 2 values; 4 control points of degree 3 need 8");
    fails("cstype bezier\ndeg 2\ncurv 0 1 1 2 3 4\nend\n", "a Bezier curve of degree 2 needs 2 k + 1 control points (k segments), got 4");
    fails("cstype bspline\ndeg 0\n", "line 6: degree 0 is outside 1..31");
    fails("cstype bspline\ndeg 2000000000\n", "line 6: degree 2000000000 is outside 1..31");
    fails("cstype bspline\ndeg 3\ncurv 0 1 1 2 3 4\n", "line 7: the curve begun here has no 'end'");
    fails("cstype bspline\ndeg 3\ncurv 0 1 1 2 3 4\ncurv 0 1 1 2 3 4\n", "line 8: 'curv' before the 'end' of the curve begun on line 7");
    fails("curv 0 1 1 2 3 4\nend\n", "line 5: 'curv' before any 'cstype'");
    fails("cstype bspline\ncurv 0 1 1\nend\n", "line 6: 'curv' needs u0 u1 and at least two control point indices");
    fails("cstype nurbs\n", "line 5: unknown cstype 'nurbs'");
    fails("parm u 0 1\n", "line 5: 'parm' outside a curve");
    fails("end\n", "line 5: 'end' without a 'curv'");
    fails("cstype bspline\ndeg 3\ncurv 0 x 1 2 3 4\nend\n", "line 7: 'x' is not a valid number (curv u1)");
    fails("cstype rat bspline\ndeg 3\nv 0 0 1 0\ncurv 0 1 1 2 3 5\nend\n", "control point 4 has weight 0; a rational curve needs weights above 0");
    ReadOptions one;
    one.curveSamples = 1;
    REQUIRE_THROWS_WITH(readObj(test::writeBytes("bad_curve.obj", v4 + "cstype bezier\ndeg 3\ncurv 0 1 1 2 3 4\nend\n"), one),
                        Contains("a sample count of 1 makes no strand"));
}

TEST_CASE("writeObj: the header names the up axis the data has, not always +Y", "[io][units]")
{
    StrandSet s = test::sampleStrands(false);
    const std::string out = test::tempPath("up.obj");
    writeObj(out, s);
    REQUIRE_THAT(test::readBytes(out), Contains("up axis not declared by the source (Blender's importer takes +Y as up; Z-up data: vdbhair convert --up z)"));
    s.upAxis = 'Z';
    writeObj(out, s);
    REQUIRE_THAT(test::readBytes(out), Contains("root to tip, +Z up (import into Blender with Up: Z)"));
    s.upAxis = 'Y';
    writeObj(out, s);
    REQUIRE_THAT(test::readBytes(out), Contains("root to tip, +Y up;"));
}
