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
