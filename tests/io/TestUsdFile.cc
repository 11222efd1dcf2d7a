#include "../TestUtil.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/io/StrandIO.h>
#include <vdbhair/io/UsdFile.h>

using namespace vdbhair;
using Catch::Matchers::Contains;

TEST_CASE("writeUsda/readUsda: positions, widths, colours and opacity round-trip", "[io][usd]")
{
    const StrandSet s = test::sampleStrands(true);
    const std::string path = test::tempPath("rt.usda");
    writeUsda(path, s);
    const std::string text = test::readBytes(path);
    REQUIRE(text.rfind("#usda 1.0\n", 0) == 0);
    REQUIRE_THAT(text, Contains("def BasisCurves \"hair\""));
    REQUIRE_THAT(text, Contains("uniform token type = \"linear\""));
    REQUIRE_THAT(text, Contains("int[] curveVertexCounts = [17, 2, 33]"));
    REQUIRE_THAT(text, Contains("upAxis = \"Y\""));
    REQUIRE_THAT(text, Contains("metersPerUnit = 0.01"));
    const StrandSet r = readUsda(path);
    test::requireSameStrands(s, r);  // shortest round-trip decimals: exact
    REQUIRE(r.thickness == s.thickness);
    REQUIRE(r.color == s.color);
    REQUIRE(r.transparency.size() == s.transparency.size());
    // Written as opacity = 1 - transparency: back within float rounding.
    for (std::size_t v = 0; v < s.numVertices(); ++v) REQUIRE(r.transparency[v] == Approx(s.transparency[v]).margin(1e-7));
}

TEST_CASE("writeUsda/readUsda: defaults become constant primvars and come back", "[io][usd]")
{
    StrandSet s = test::sampleStrands(false);
    s.defaults.thickness = 0.1f;
    s.defaults.transparency = 0.25f;
    s.defaults.color = Vec3f(0.8f, 0.4f, 0.1f);
    const std::string path = test::tempPath("defaults.usda");
    UsdWriteOptions opts;
    opts.upAxis = "Z";
    opts.metersPerUnit = 1.0;
    writeUsda(path, s, opts);
    REQUIRE_THAT(test::readBytes(path), Contains("float[] widths = [0.1] (\n        interpolation = \"constant\""));
    ReadReport report;
    const StrandSet r = readUsda(path, {}, &report);
    test::requireSameStrands(s, r);
    REQUIRE(r.thickness.empty());
    REQUIRE(r.color.empty());
    REQUIRE(r.transparency.empty());
    REQUIRE(r.defaults.thickness == 0.1f);
    REQUIRE(r.defaults.transparency == 0.25f);
    REQUIRE(r.defaults.color == Vec3f(0.8f, 0.4f, 0.1f));
    REQUIRE(report.warnings.size() == 1);
    REQUIRE_THAT(report.warnings[0], Contains("upAxis is Z"));
    REQUIRE_THROWS_WITH(writeUsda(path, s, UsdWriteOptions{"X", 0.01}), Contains("up axis 'X' must be Y or Z"));
}

TEST_CASE("readUsda: files written by other tools (nested prims, metadata, uniform primvars, comments)", "[io][usd]")
{
    const std::string text = R"(#usda 1.0
(
    doc = """Blender v3.4 """
    metersPerUnit = 1
    upAxis = "Y"
)

def Xform "root" (
    kind = "component"
)
{
    matrix4d xformOp:transform = ( (1, 0, 0, 0), (0, 1, 0, 0), (0, 0, 1, 0), (0, 0, 0, 1) )
    uniform token[] xformOpOrder = ["xformOp:transform"]

    def Mesh "head" { int[] faceVertexCounts = [3] }
    def BasisCurves "groom" (
        prepend apiSchemas = ["MaterialBindingAPI"]
    )
    {
        uniform token type = "linear"   # two curves
        int[] curveVertexCounts = [2, 3]
        point3f[] points = [(0, 0, 0), (0, 1, 0), (1, 0, 0), (1, 1, 0), (1, 2, -1e-1)]
        float[] widths = [0.5, 0.25] (interpolation = "uniform")
        color3f[] primvars:displayColor = [(1, 0, 0)]
        rel material:binding = </root/mat>
        custom string userProperties:note = "a } in a string"
    }
    def BasisCurves "more"
    {
        int[] curveVertexCounts = [2]
        point3f[] points = [(5, 5, 5), (6, 6, 6)]
    }
}
)";
    ReadReport report;
    const StrandSet s = readUsda(test::writeBytes("other.usda", text), {}, &report);
    REQUIRE(s.numStrands() == 3);
    REQUIRE(s.size(0) == 2);
    REQUIRE(s.size(1) == 3);
    REQUIRE(s.positions[4] == Vec3f(1.f, 2.f, -0.1f));
    REQUIRE(s.thickness.size() == 7);
    REQUIRE(s.thickness[0] == 0.5f);
    REQUIRE(s.thickness[4] == 0.25f);
    REQUIRE(s.defaults.color == Vec3f(1.f, 0.f, 0.f));  // displayColor is constant unless told
    REQUIRE(s.root(2) == Vec3f(5.f));
}

TEST_CASE("readUsda: each kind of bad input has its own error", "[io][usd]")
{
    auto usda = [](const std::string& body) { return "#usda 1.0\ndef BasisCurves \"c\"\n{\n" + body + "}\n"; };
    REQUIRE_THROWS_AS(readUsda(test::writeBytes("b0.usda", "PXR-USDC binary")), UnsupportedError);
    REQUIRE_THROWS_WITH(readUsda(test::writeBytes("b0.usd", "PXR-USDC binary")), Contains("a binary USD (crate, PXR-USDC) file; vdbhair reads USD text"));
    REQUIRE_THROWS_WITH(readUsda(test::writeBytes("b0b.usda", "hello")), Contains("not a USD text file"));
    REQUIRE_THROWS_WITH(readUsda(test::writeBytes("b0c.usda", "#usda 1.0\n(\n    metersPerUnit = -1\n)\n")),
                        Contains("metersPerUnit must be one positive number"));
    REQUIRE_THROWS_WITH(readUsda(test::writeBytes("b1.usda", "#usda 1.0\ndef Mesh \"m\" {}\n")), Contains("no 'def BasisCurves' prim"));
    REQUIRE_THROWS_WITH(readUsda(test::writeBytes("b2.usda", usda("int[] curveVertexCounts = [3]\npoint3f[] points = [(0,0,0), (1,1,1)]\n"))),
                        Contains("line 4: prim \"c\" (line 2): curveVertexCounts add up to 3 but there are 2 points"));
    REQUIRE_THROWS_WITH(readUsda(test::writeBytes("b3.usda", usda("int[] curveVertexCounts = [2]\n"))), Contains("BasisCurves without points"));
    REQUIRE_THROWS_WITH(readUsda(test::writeBytes("b4.usda", usda("int[] curveVertexCounts = [2]\npoint3f[] points = [(0,0,0), (1,1,1)]\nfloat[] widths = [1, 2, 3]\n"))),
                        Contains("vertex widths needs one value per point (2), got 3"));
    REQUIRE_THROWS_WITH(readUsda(test::writeBytes("b5.usda", usda("int[] curveVertexCounts = [2\n"))), Contains("expected ',' or ']' in a value"));
    REQUIRE_THROWS_WITH(readUsda(test::writeBytes("b6.usda", usda("int[] curveVertexCounts = [2]\npoint3f[] points = [(0,0,0), (1,nan,1)]\n"))),
                        Contains("non-finite coordinate"));
}

TEST_CASE("readUsda: values and prims nest at most 128 deep, so no file runs the parser out of stack (fuzz_usda, issue 22)", "[io][usd][fuzz]")
{
    // fuzz_usda's finding: metadata opening 7,000 '{' overflowed the stack of the recursive parser.
    REQUIRE_THROWS_WITH(readUsda(test::regressionInput("fuzz_usda_nested.usda")),
                        Contains("line 5: values nested more than 128 deep; USD text here nests at most 128 levels"));
    const auto nestedValue = [](int n) {
        return "#usda 1.0\ndef BasisCurves \"c\" {\n    int[] curveVertexCounts = " + std::string(std::size_t(n), '[') + "2" +
               std::string(std::size_t(n), ']') + "\n}\n";
    };
    REQUIRE_THROWS_WITH(readUsda(test::writeBytes("deep_value.usda", nestedValue(129))), Contains("values nested more than 128 deep"));
    // 128 levels parse (and fail later, for what the value is, not for its depth).
    REQUIRE_THROWS_WITH(readUsda(test::writeBytes("ok_value.usda", nestedValue(128))), !Contains("nested"));
    const auto nestedPrims = [](int n) {
        std::string s = "#usda 1.0\n";
        for (int i = 0; i < n; ++i) s += "def Xform \"x\" {\n";
        return s + std::string(std::size_t(n), '}') + "\n";
    };
    REQUIRE_THROWS_WITH(readUsda(test::writeBytes("deep_prims.usda", nestedPrims(129))), Contains("line 130: prims nested more than 128 deep"));
    REQUIRE_THROWS_WITH(readUsda(test::writeBytes("ok_prims.usda", nestedPrims(128))), !Contains("nested"));
}

TEST_CASE("readUsda/writeUsda: the stage's metersPerUnit and upAxis are carried, USD to USD keeps them", "[io][usd][units]")
{
    const std::string text = "#usda 1.0\n(\n    metersPerUnit = 1\n    upAxis = \"Z\"\n)\ndef BasisCurves \"c\"\n{\n"
                             "    int[] curveVertexCounts = [2]\n    point3f[] points = [(0, 0, 0), (0, 0, 0.3)]\n}\n";
    ReadReport report;
    const StrandSet s = readUsda(test::writeBytes("units.usda", text), {}, &report);
    REQUIRE(s.metersPerUnit == 1.0);
    REQUIRE(s.upAxis == 'Z');
    REQUIRE(s.positions[1] == Vec3f(0.f, 0.f, 0.3f));  // declared, never applied
    const std::string out = test::tempPath("units_out.usda");
    writeUsda(out, s);
    const std::string written = test::readBytes(out);
    REQUIRE_THAT(written, Contains("metersPerUnit = 1\n"));
    REQUIRE_THAT(written, Contains("upAxis = \"Z\""));
    const StrandSet back = readUsda(out);
    REQUIRE(back.metersPerUnit == 1.0);
    REQUIRE(back.upAxis == 'Z');
    // An explicit choice wins; a stage without metadata has USD's fallbacks (centimetres, +Y).
    UsdWriteOptions opts;
    opts.metersPerUnit = 0.001;
    opts.upAxis = "Y";
    writeUsda(out, s, opts);
    REQUIRE_THAT(test::readBytes(out), Contains("metersPerUnit = 0.001\n"));
    const StrandSet plain = readUsda(test::writeBytes("plain.usda", "#usda 1.0\ndef BasisCurves \"c\"\n{\n"
                                                      "    int[] curveVertexCounts = [2]\n    point3f[] points = [(0, 0, 0), (0, 1, 0)]\n}\n"));
    REQUIRE(plain.metersPerUnit == 0.01);
    REQUIRE(plain.upAxis == 'Y');
    // Other formats declare nothing: 0.01 is written, as before.
    writeUsda(out, test::sampleStrands(false));
    REQUIRE_THAT(test::readBytes(out), Contains("metersPerUnit = 0.01\n"));
}

TEST_CASE("writeUsda: widths of strands without thickness: the width given, the file's default, else a thousandth of the diagonal", "[io][usd][units]")
{
    StrandSet s;
    s.addStrand(std::vector<Vec3f>{Vec3f(0.f), Vec3f(3.f, 0.f, 0.f)});
    s.addStrand(std::vector<Vec3f>{Vec3f(0.f, 4.f, 0.f), Vec3f(0.f, 4.f, 12.f)});  // diagonal 13
    REQUIRE(automaticUsdWidth(s) == Approx(0.013f));
    const std::string out = test::tempPath("widths.usda");
    writeUsda(out, s);
    REQUIRE_THAT(test::readBytes(out), Contains("float[] widths = [0.013] (\n        interpolation = \"constant\""));
    UsdWriteOptions opts;
    opts.width = 0.5f;
    writeUsda(out, s, opts);
    REQUIRE_THAT(test::readBytes(out), Contains("float[] widths = [0.5] (\n        interpolation = \"constant\""));
    // Written for display: vdbhair reads the strands' own default back (1), exactly.
    REQUIRE_THAT(test::readBytes(out), Contains("custom bool vdbhair_display_width = true"));
    REQUIRE(readUsda(out).defaults.thickness == 1.f);
    StrandSet declared = s;
    declared.defaults.thickness = 0.07f;  // a cyHair header's
    writeUsda(out, declared);
    REQUIRE_THAT(test::readBytes(out), Contains("float[] widths = [0.07] (\n        interpolation = \"constant\""));
    StrandSet thick = s;
    thick.thickness = {0.1f, 0.2f, 0.3f, 0.4f};
    writeUsda(out, thick, opts);  // per-vertex thickness wins over --width
    REQUIRE_THAT(test::readBytes(out), Contains("float[] widths = [0.1, 0.2, 0.3, 0.4] (\n        interpolation = \"vertex\""));
    opts.width = -1.f;
    REQUIRE_THROWS_WITH(writeUsda(out, s, opts), Contains("width -1.000000 must be positive and finite"));
}

TEST_CASE("writeUsda: a colour, opacity or width the same at every vertex is written once, constant", "[io][usd]")
{
    StrandSet s = test::sampleStrands(false);
    s.color.assign(s.numVertices(), Vec3f(0.2f, 0.1f, 0.05f));
    s.transparency.assign(s.numVertices(), 0.5f);
    s.thickness.assign(s.numVertices(), 0.02f);
    const std::string out = test::tempPath("constant.usda");
    writeUsda(out, s);
    const std::string text = test::readBytes(out);
    REQUIRE_THAT(text, Contains("color3f[] primvars:displayColor = [(0.2, 0.1, 0.05)] (\n        interpolation = \"constant\""));
    REQUIRE_THAT(text, Contains("float[] primvars:displayOpacity = [0.5] (\n        interpolation = \"constant\""));
    REQUIRE_THAT(text, Contains("float[] widths = [0.02] (\n        interpolation = \"constant\""));
    const StrandSet r = readUsda(out);
    REQUIRE(r.colorAt(5) == Vec3f(0.2f, 0.1f, 0.05f));
    REQUIRE(r.thicknessAt(7) == 0.02f);
    REQUIRE(r.transparencyAt(3) == Approx(0.5f));
}

TEST_CASE("readStrands: a .usd file of USD text reads as .usda; .usd is not written", "[io][usd]")
{
    const StrandSet s = test::sampleStrands(true);
    const std::string usda = test::tempPath("text.usda");
    writeUsda(usda, s);
    const std::string usd = test::writeBytes("text.usd", test::readBytes(usda));
    test::requireSameStrands(s, readStrands(usd));
    REQUIRE(strandFormatFromPath(usd) == StrandFormat::Usda);
    REQUIRE_THROWS_WITH(writeStrands(test::tempPath("out.usd"), s), Contains("is read-only in vdbhair"));
}

TEST_CASE("readUsda: xformOps of the prim and its parents are applied as USD composes them", "[io][usd][xform]")
{
    // Parent: translate, rotate 90 degrees about Z, scale 2 (scale applied first); child: +Y.
    const std::string text = R"(#usda 1.0
def Xform "root"
{
    double3 xformOp:translate = (10, 0, 0)
    float3 xformOp:rotateXYZ = (0, 0, 90)
    float3 xformOp:scale = (2, 2, 2)
    uniform token[] xformOpOrder = ["xformOp:translate", "xformOp:rotateXYZ", "xformOp:scale"]
    def BasisCurves "hair"
    {
        double3 xformOp:translate = (0, 1, 0)
        uniform token[] xformOpOrder = ["xformOp:translate"]
        uniform token type = "linear"
        int[] curveVertexCounts = [2]
        point3f[] points = [(0, 0, 0), (1, 0, 0)]
        float[] widths = [0.5] (interpolation = "constant")
    }
    def Xform "pivoted"
    {
        double3 xformOp:translate = (100, 0, 0)
        uniform token[] xformOpOrder = ["xformOp:translate"]
        def BasisCurves "reset"
        {
            uniform token[] xformOpOrder = ["!resetXformStack!", "xformOp:translate:pivot", "xformOp:rotateY", "!invert!xformOp:translate:pivot"]
            double3 xformOp:translate:pivot = (1, 0, 0)
            float xformOp:rotateY = 180
            uniform token type = "linear"
            int[] curveVertexCounts = [2]
            point3f[] points = [(1, 0, 0), (2, 0, 0)]
        }
        def BasisCurves "oriented"
        {
            quatf xformOp:orient = (0.70710678, 0.70710678, 0, 0)
            matrix4d xformOp:transform = ( (1, 0, 0, 0), (0, 1, 0, 0), (0, 0, 1, 0), (0, 0, 5, 1) )
            float3 xformOp:scale = (7, 7, 7)
            uniform token[] xformOpOrder = ["xformOp:transform", "xformOp:orient"]
            uniform token type = "linear"
            int[] curveVertexCounts = [2]
            point3f[] points = [(0, 1, 0), (0, 2, 0)]
        }
    }
}
)";
    ReadReport report;
    const StrandSet s = readUsda(test::writeBytes("xform.usda", text), {}, &report);
    REQUIRE(s.numStrands() == 3);
    auto near = [](const Vec3f& a, const Vec3f& b) { return (a - b).length() < 1e-5f; };
    // (0,0,0) -> +Y (0,1,0) -> x2 (0,2,0) -> 90 about Z (-2,0,0) -> +10 X (8,0,0).
    REQUIRE(near(s.positions[0], Vec3f(8.f, 0.f, 0.f)));
    REQUIRE(near(s.positions[1], Vec3f(8.f, 2.f, 0.f)));
    REQUIRE(s.defaults.thickness == Approx(1.0f));  // widths scale with the transform
    // The parents' transforms do not apply after !resetXformStack!; 180 degrees about Y around (1,0,0).
    REQUIRE(near(s.positions[2], Vec3f(1.f, 0.f, 0.f)));
    REQUIRE(near(s.positions[3], Vec3f(0.f, 0.f, 0.f)));
    // Three levels: orient (90 degrees about X: (0,1,0) -> (0,0,1)) first, then the matrix (+5 Z),
    // then "pivoted" (+100 X), then "root" (x2, 90 about Z, +10 X): (0,0,6) -> (100,0,6) ->
    // (200,0,12) -> (0,200,12) -> (10,200,12). The scale is not in xformOpOrder: not applied.
    REQUIRE(near(s.positions[4], Vec3f(10.f, 200.f, 12.f)));
    REQUIRE(near(s.positions[5], Vec3f(10.f, 200.f, 14.f)));
    REQUIRE(report.warnings.empty());

    // An op the order names without a value is skipped with a warning; a bad value is an error.
    const std::string missing = R"(#usda 1.0
def BasisCurves "c"
{
    uniform token[] xformOpOrder = ["xformOp:translate"]
    uniform token type = "linear"
    int[] curveVertexCounts = [2]
    point3f[] points = [(0, 0, 0), (1, 0, 0)]
}
)";
    ReadReport r2;
    const StrandSet m = readUsda(test::writeBytes("xform_missing.usda", missing), {}, &r2);
    REQUIRE(m.positions[1] == Vec3f(1.f, 0.f, 0.f));
    REQUIRE(r2.warnings.size() == 1);
    REQUIRE_THAT(r2.warnings[0], Contains("xformOpOrder names \"xformOp:translate\", which has no value"));
    std::string bad = missing;
    bad.insert(bad.find("    uniform token type"), "    double3 xformOp:translate = (1, 2)\n");
    REQUIRE_THROWS_WITH(readUsda(test::writeBytes("xform_bad.usda", bad)), Contains("xformOp:translate: translate needs 3 number(s), got 2"));
    std::string singular = missing;
    singular.replace(singular.find("[\"xformOp:translate\"]"), 21, "[\"!invert!xformOp:scale\"]");
    singular.insert(singular.find("    uniform token type"), "    float3 xformOp:scale = (1, 0, 1)\n");
    REQUIRE_THROWS_WITH(readUsda(test::writeBytes("xform_singular.usda", singular)), Contains("!invert!xformOp:scale is not invertible"));
}

namespace {
std::string cubicUsda(const std::string& basis, const std::string& wrap, const std::string& points, const std::string& extra = "")
{
    const std::size_t n = std::size_t(std::count(points.begin(), points.end(), '('));
    return "#usda 1.0\ndef BasisCurves \"c\"\n{\n    uniform token type = \"cubic\"\n    uniform token basis = \"" + basis +
           "\"\n    uniform token wrap = \"" + wrap + "\"\n    int[] curveVertexCounts = [" + std::to_string(n) +
           "]\n    point3f[] points = [" + points + "]\n" + extra + "}\n";
}
} // namespace

TEST_CASE("readUsda: cubic BasisCurves (bezier, bspline, catmullRom; nonperiodic, pinned, periodic) are evaluated", "[io][usd][cubic]")
{
    const std::string line = "(0,0,0), (1,0,0), (2,0,0), (3,0,0), (4,0,0), (5,0,0)";
    auto onAxis = [](const StrandSet& s) {
        for (const Vec3f& p : s.positions) if (std::abs(p.y()) > 1e-6f || std::abs(p.z()) > 1e-6f) return false;
        return true;
    };
    // A uniform B-spline over points on a line is the line from P1 to P4; pinned, from P0 to P5.
    const StrandSet b = readUsda(test::writeBytes("bspline.usda", cubicUsda("bspline", "nonperiodic", line)));
    REQUIRE(onAxis(b));
    REQUIRE(b.positions.front().x() == Approx(1.f));
    REQUIRE(b.positions.back().x() == Approx(4.f));
    const StrandSet bp = readUsda(test::writeBytes("bspline_pinned.usda", cubicUsda("bspline", "pinned", line)));
    REQUIRE(onAxis(bp));
    REQUIRE(bp.positions.front().x() == Approx(0.f).margin(1e-6));
    REQUIRE(bp.positions.back().x() == Approx(5.f));

    // Catmull-Rom passes through every control point but the first and the last.
    const std::string zigzag = "(0,0,0), (1,1,0), (2,0,0), (3,1,0), (4,0,0), (5,1,0)";
    const StrandSet c = readUsda(test::writeBytes("catmull.usda", cubicUsda("catmullRom", "nonperiodic", zigzag)));
    for (const Vec3f& q : {Vec3f(1, 1, 0), Vec3f(2, 0, 0), Vec3f(3, 1, 0), Vec3f(4, 0, 0)}) {
        REQUIRE(std::any_of(c.positions.begin(), c.positions.end(), [&](const Vec3f& p) { return (p - q).length() < 1e-5f; }));
    }
    REQUIRE((c.positions.front() - Vec3f(1, 1, 0)).length() < 1e-5f);
    REQUIRE((c.positions.back() - Vec3f(4, 0, 0)).length() < 1e-5f);

    // A cubic Bezier quarter circle (handles 0.5523 r long) keeps within 0.03 % of the radius.
    const std::string quarter = "(1,0,0), (1,0.5523,0), (0.5523,1,0), (0,1,0)";
    const StrandSet q = readUsda(test::writeBytes("bezier.usda", cubicUsda("bezier", "nonperiodic", quarter)));
    REQUIRE(q.size(0) >= 5);
    for (const Vec3f& p : q.positions) REQUIRE(p.length() == Approx(1.f).margin(3e-4));
    REQUIRE((q.positions.front() - Vec3f(1, 0, 0)).length() < 1e-6f);
    REQUIRE((q.positions.back() - Vec3f(0, 1, 0)).length() < 1e-6f);
    ReadOptions ten;
    ten.curveSamples = 10;  // --curve-samples
    REQUIRE(readUsda(test::writeBytes("bezier10.usda", cubicUsda("bezier", "nonperiodic", quarter)), ten).size(0) == 10);

    // Periodic: the loop closes.
    const std::string square = "(0,0,0), (1,0,0), (1,1,0), (0,1,0)";
    const StrandSet loop = readUsda(test::writeBytes("periodic.usda", cubicUsda("bspline", "periodic", square)));
    REQUIRE((loop.positions.front() - loop.positions.back()).length() < 1e-5f);

    // Widths per control point follow the curve; varying ones are one per segment end.
    const StrandSet w = readUsda(test::writeBytes("bspline_w.usda", cubicUsda("bspline", "nonperiodic", line,
                                 "    float[] widths = [1, 1, 2, 3, 4, 4] (interpolation = \"vertex\")\n")));
    REQUIRE(w.thickness.size() == w.numVertices());
    REQUIRE(w.thickness.front() == Approx(1.f));
    REQUIRE(w.thickness.back() == Approx(4.f));
    REQUIRE(std::is_sorted(w.thickness.begin(), w.thickness.end()));
    const StrandSet wv = readUsda(test::writeBytes("bspline_wv.usda", cubicUsda("bspline", "nonperiodic", line,
                                  "    float[] widths = [1, 2, 3, 4] (interpolation = \"varying\")\n")));
    REQUIRE(wv.thickness.front() == Approx(1.f));
    REQUIRE(wv.thickness.back() == Approx(4.f));
    REQUIRE_THROWS_WITH(readUsda(test::writeBytes("bspline_wv5.usda", cubicUsda("bspline", "nonperiodic", line,
                                 "    float[] widths = [1, 2, 3, 4, 5] (interpolation = \"varying\")\n"))),
                        Contains("varying widths needs one value per segment end (4), got 5"));

    // One width without interpolation is constant; an older writer's widths:interpolation attribute counts.
    const StrandSet one = readUsda(test::writeBytes("width1.usda", cubicUsda("catmullRom", "pinned", zigzag, "    float[] widths = [0.2]\n")));
    REQUIRE(one.thickness.empty());
    REQUIRE(one.defaults.thickness == 0.2f);
    const StrandSet attr = readUsda(test::writeBytes("width_attr.usda", cubicUsda("catmullRom", "pinned", zigzag,
                                    "    float[] widths = [0.3]\n    uniform token widths:interpolation = \"constant\"\n")));
    REQUIRE(attr.defaults.thickness == 0.3f);
    REQUIRE((attr.positions.front() - Vec3f(0, 0, 0)).length() < 1e-5f);  // pinned: from the first point
    REQUIRE((attr.positions.back() - Vec3f(5, 1, 0)).length() < 1e-5f);

    // Errors and fallbacks.
    REQUIRE_THROWS_WITH(readUsda(test::writeBytes("bezier5.usda", cubicUsda("bezier", "nonperiodic", "(0,0,0), (1,0,0), (2,0,0), (3,0,0), (4,0,0)"))),
                        Contains("curve 0 (cubic bezier, nonperiodic): a Bezier curve of degree 3 needs 3 k + 1 control points"));
    REQUIRE_THROWS_WITH(readUsda(test::writeBytes("wrapx.usda", cubicUsda("bezier", "loop", quarter))), Contains("wrap \"loop\"; expected nonperiodic, periodic or pinned"));
    ReadReport hermite;
    const StrandSet h = readUsda(test::writeBytes("hermite.usda", cubicUsda("hermite", "nonperiodic", quarter)), {}, &hermite);
    REQUIRE(h.size(0) == 4);
    REQUIRE_THAT(hermite.warnings.at(0), Contains("cubic basis \"hermite\" (deprecated in USD) is not evaluated"));
}

TEST_CASE("readUsda: time-sampled attributes are read at their first sample, with a warning", "[io][usd]")
{
    const std::string text = R"(#usda 1.0
def BasisCurves "c"
{
    uniform token type = "linear"
    int[] curveVertexCounts = [2]
    point3f[] points.timeSamples = {
        2: [(0, 0, 0), (0, 2, 0)],
        1: [(0, 0, 0), (0, 1, 0)],
    }
    point3f[] points = [(9, 9, 9), (9, 9, 8)]
}
)";
    ReadReport report;
    const StrandSet s = readUsda(test::writeBytes("samples.usda", text), {}, &report);
    REQUIRE(s.positions[1] == Vec3f(0.f, 1.f, 0.f));
    REQUIRE(report.warnings.size() == 1);
    REQUIRE_THAT(report.warnings[0], Contains("1 time-sampled attribute(s) were read at their first sample"));
}
