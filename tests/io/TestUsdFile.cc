#include "../TestUtil.h"

#include <vdbhair/Exceptions.h>
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
    REQUIRE_THROWS_WITH(readUsda(test::writeBytes("b0.usda", "PXR-USDC binary")), Contains("not a USD text file"));
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
