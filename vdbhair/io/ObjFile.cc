#include "ObjFile.h"

#include <vdbhair/Memory.h>
#include <vdbhair/io/MeshFile.h>

#include <vdbhair/Version.h>
#include <vdbhair/io/EdgeChains.h>
#include <vdbhair/io/FileUtil.h>
#include <vdbhair/io/FreeFormCurve.h>
#include <vdbhair/io/TextScanner.h>

#include <algorithm>
#include <charconv>
#include <limits>

namespace vdbhair {

namespace {

/// The position on a 'v' line (vertex number @a index, for the error message).
Vec3f objPosition(TextScanner& text, const std::vector<std::string_view>& tok, std::size_t index, const std::string& where)
{
    if (tok.size() < 4) text.fail("a 'v' line needs 3 coordinates, got " + std::to_string(tok.size() - 1));
    const Vec3f p(text.toFloat(tok[1], "x"), text.toFloat(tok[2], "y"), text.toFloat(tok[3], "z"));
    checkFinite(p, index, where, "line " + std::to_string(text.line()));
    return p;
}

/// The 0-based vertex an index token names ("i", "i/t", "i//n", "i/t/n"; 1-based, negative
/// counting back from the @a defined vertices so far).
std::uint32_t objVertexIndex(TextScanner& text, std::string_view t, std::size_t defined)
{
    if (const std::size_t slash = t.find('/'); slash != std::string_view::npos) t = t.substr(0, slash);
    const std::int64_t idx = text.toInt(t, "vertex index");
    const std::int64_t n = std::int64_t(defined);
    const std::int64_t resolved = idx > 0 ? idx - 1 : n + idx;
    if (idx == 0 || resolved < 0 || resolved >= n) {
        text.fail("vertex index " + std::to_string(idx) + " is out of range: " + std::to_string(n) +
                  " vertices are defined so far (1-based, negative counts back)");
    }
    return std::uint32_t(resolved);
}

} // namespace

ObjLineStyle objLineStyleFromName(const std::string& name)
{
    if (name == "edges") return ObjLineStyle::Edges;
    if (name == "polylines") return ObjLineStyle::Polylines;
    throw ValueError("OBJ line style '" + name + "' is not one of edges (Blender), polylines (Houdini)");
}

StrandSet readObj(const std::string& path, const ReadOptions& opts, ReadReport* report)
{
    const std::string where = "readObj(" + path + ")";
    const std::vector<char> bytes = readFileBytes(path, where, opts.interrupter);
    TextScanner text(bytes, where);

    // Pass 1: vertices, every `l` element as edges between consecutive vertices, and every
    // free-form curve (`curv` ... `end`) evaluated to a polyline as soon as it ends.
    std::vector<Vec3f> vertices;
    std::vector<Vec3f> colors;
    std::vector<double> weights;  // `v x y z w`: filled (with 1) only once a vertex has a weight
    bool anyColor = false;
    EdgeList edges;
    std::size_t lineElements = 0, ignored = 0, curves = 0, skippedFreeForm = 0;
    std::size_t skippedFreeFormLine = 0;
    std::vector<std::string_view> tok, more;
    std::vector<std::uint32_t> element;

    // Free-form state: the attributes in force (cstype, deg) and the curve being read.
    FreeFormCurve attrs;
    bool haveCstype = false;
    bool inCurve = false;
    std::size_t curveLine = 0;
    FreeFormCurve curve;
    std::vector<std::uint32_t> curveIndices;
    std::vector<Vec3f> curvePoints;
    std::vector<std::uint32_t> curveOffsets{0};
    auto curveFail = [&](const std::string& rule) {
        throw FormatError(where + ": line " + std::to_string(curveLine) + ": curve: " + rule);
    };

    InterruptPoll poll(opts.interrupter, where);
    while (text.nextLine(tok)) {
        poll();
        // A line ending in a backslash continues on the next (the OBJ specification; Maya breaks
        // long curv and parm lines so).
        while (!tok.empty() && tok.back() == "\\" && text.nextLine(more)) {
            tok.pop_back();
            tok.insert(tok.end(), more.begin(), more.end());
        }
        if (!tok.empty() && tok.back() == "\\") tok.pop_back();
        if (tok.empty()) continue;
        const std::string_view key = tok[0];
        if (key == "v") {
            vertices.push_back(objPosition(text, tok, vertices.size(), where));
            Vec3f c(0.5f);
            if (tok.size() >= 7) {
                c = Vec3f(text.toFloat(tok[4], "red"), text.toFloat(tok[5], "green"), text.toFloat(tok[6], "blue"));
                anyColor = true;
            } else if (tok.size() == 5) {
                const double w = text.toDouble(tok[4], "weight");
                if (weights.empty() && w != 1.0) weights.assign(vertices.size() - 1, 1.0);
                if (!weights.empty()) weights.push_back(w);
            }
            if (!weights.empty() && weights.size() < vertices.size()) weights.push_back(1.0);
            colors.push_back(c);
        } else if (key == "l") {
            if (tok.size() < 2) text.fail("an 'l' element needs at least one vertex index");
            ++lineElements;
            element.clear();
            for (std::size_t j = 1; j < tok.size(); ++j) element.push_back(objVertexIndex(text, tok[j], vertices.size()));
            const std::uint32_t line = std::uint32_t(std::min<std::size_t>(text.line(), 0xffffffffu));
            if (element.size() == 1) edges.singles.push_back({element[0], line});
            for (std::size_t j = 0; j + 1 < element.size(); ++j) {
                if (element[j] == element[j + 1]) { ++edges.selfEdges; continue; }
                edges.edges.push_back({std::min(element[j], element[j + 1]), std::max(element[j], element[j + 1]), line});
            }
        } else if (key == "cstype") {
            if (tok.size() < 2 || tok.size() > 3 || (tok.size() == 3 && tok[1] != "rat")) {
                text.fail("'cstype' needs a type, optionally after 'rat': cstype [rat] bspline|bezier|cardinal");
            }
            const std::string_view type = tok.back();
            attrs.rational = tok.size() == 3;
            if (type == "bspline") attrs.basis = CurveBasis::BSpline;
            else if (type == "bezier") attrs.basis = CurveBasis::Bezier;
            else if (type == "cardinal") attrs.basis = CurveBasis::Cardinal;
            else if (type == "taylor" || type == "bmatrix") {
                throw UnsupportedError(where + ": line " + std::to_string(text.line()) + ": cstype " + std::string(type) +
                                       " is not supported (bspline, bezier and cardinal curves are; convert the curves to one of them or to polylines)");
            } else {
                text.fail("unknown cstype '" + std::string(type) + "' (the OBJ types are bspline, bezier, cardinal, taylor, bmatrix)");
            }
            haveCstype = true;
        } else if (key == "deg") {
            if (tok.size() < 2) text.fail("'deg' needs a degree");
            const std::int64_t d = text.toInt(tok[1], "degree");
            if (d < 1 || d > kMaxCurveDegree) {
                text.fail("degree " + std::to_string(d) + " is outside 1.." + std::to_string(kMaxCurveDegree) + " (the degrees this reader evaluates)");
            }
            attrs.degree = int(d);
        } else if (key == "curv") {
            if (inCurve) text.fail("'curv' before the 'end' of the curve begun on line " + std::to_string(curveLine));
            if (!haveCstype) text.fail("'curv' before any 'cstype' (cstype bspline, bezier or cardinal)");
            if (tok.size() < 5) text.fail("'curv' needs u0 u1 and at least two control point indices, got " + std::to_string(tok.size() - 1) + " values");
            inCurve = true;
            curveLine = text.line();
            curve = attrs;
            curve.u0 = text.toDouble(tok[1], "curv u0");
            curve.u1 = text.toDouble(tok[2], "curv u1");
            curveIndices.clear();
            for (std::size_t j = 3; j < tok.size(); ++j) curveIndices.push_back(objVertexIndex(text, tok[j], vertices.size()));
        } else if (key == "parm") {
            if (!inCurve) text.fail("'parm' outside a curve (between 'curv' and 'end')");
            if (tok.size() < 2 || tok[1] != "u") text.fail("a curve takes 'parm u' values only");
            curve.parms.clear();
            for (std::size_t j = 2; j < tok.size(); ++j) curve.parms.push_back(text.toDouble(tok[j], "parm u"));
        } else if (key == "end") {
            if (!inCurve) text.fail("'end' without a 'curv'");
            inCurve = false;
            curve.points.clear();
            curve.weights.clear();
            for (const std::uint32_t v : curveIndices) {
                curve.points.emplace_back(vertices[v].x(), vertices[v].y(), vertices[v].z());
                curve.weights.push_back(weights.empty() ? 1.0 : weights[v]);
            }
            if (std::string rule = flattenCurve(curve, opts.curveSamples, curvePoints); !rule.empty()) curveFail(rule);
            curveOffsets.push_back(std::uint32_t(curvePoints.size()));
            ++curves;
        } else if (key == "curv2" || key == "surf") {
            // Curves on surfaces (trimming) and surfaces are not strands: skipped, up to their 'end'.
            ++skippedFreeForm;
            if (!skippedFreeFormLine) skippedFreeFormLine = text.line();
            if (inCurve) text.fail("'" + std::string(key) + "' before the 'end' of the curve begun on line " + std::to_string(curveLine));
            while (text.nextLine(tok) && !(tok.size() == 1 && tok[0] == "end")) poll();
        } else if (key[0] == '#') {
            continue;
        } else {
            ++ignored;  // f, vn, vt, vp, o, g, s, usemtl, mtllib, trim, hole, ...
        }
    }
    if (inCurve) throw FormatError(where + ": line " + std::to_string(curveLine) + ": the curve begun here has no 'end'");
    if (lineElements == 0 && curves == 0) {
        throw FormatError(where + ": no polylines: the file has no 'l' elements and no curves ('curv')" +
                          (ignored ? " (" + std::to_string(ignored) + " other lines, e.g. faces, were ignored)" : std::string()));
    }
    if (ignored && report) {
        report->warnings.push_back(where + ": " + std::to_string(ignored) + " lines other than v and l (faces, normals, groups, ...) were ignored");
    }
    if (skippedFreeForm && report) {
        report->warnings.push_back(where + ": skipped " + std::to_string(skippedFreeForm) + " curv2/surf element(s) (first on line " +
                                   std::to_string(skippedFreeFormLine) + "): curves on surfaces and surfaces are not strands");
    }

    // Strands: the chains of the `l` elements, then the curves in file order.
    StrandSet out;
    if (lineElements) {
        EdgeNaming naming;
        naming.vertexBase = 1;
        naming.place = "line";
        naming.places = "edges on lines";
        out = strandsFromEdges(vertices, anyColor ? colors : std::vector<Vec3f>{}, edges, naming, where, opts, report);
    }
    if (curves) {
        // A curve's points have no colour of their own: the default grey where the lines have colours.
        for (std::size_t i = 0; i + 1 < curveOffsets.size(); ++i) {
            out.positions.insert(out.positions.end(), curvePoints.begin() + curveOffsets[i], curvePoints.begin() + curveOffsets[i + 1]);
            if (anyColor) out.color.resize(out.positions.size(), Vec3f(0.5f));
            out.offsets.push_back(std::uint32_t(out.positions.size()));
        }
    }
    return out;
}

std::string objUpAxisWords(char upAxis)
{
    // OBJ declares no axes; Blender's importer reads +Y as up by default ("Up: Y, Forward: -Z").
    if (upAxis == 'Y') return "+Y up";
    if (upAxis == 'Z') return "+Z up (import into Blender with Up: Z)";
    return "up axis not declared by the source (Blender's importer takes +Y as up; Z-up data: vdbhair convert --up z)";
}

void writeObj(const std::string& path, const StrandSet& strands, ObjLineStyle style)
{
    const std::string where = "writeObj(" + path + ")";
    std::string out;
    reserveHugePages(out, 40 * strands.numVertices() + 16 * strands.numVertices());
    out += "# ";
    out += creatorString();
    out += ": " + std::to_string(strands.numStrands()) + " strands, " + std::to_string(strands.numVertices()) +
           " vertices, root to tip, " + objUpAxisWords(strands.upAxis) + "; " +
           (style == ObjLineStyle::Edges ? "one two-vertex 'l' edge per segment, chained per strand (Blender reads every segment)\n"
                                         : "one 'l' polyline per strand\n");
    char buf[32];
    auto putFloat = [&](float v) {
        const auto res = std::to_chars(buf, buf + sizeof buf, v);
        out.push_back(' ');
        out.append(buf, res.ptr);
    };
    auto putIndex = [&](std::size_t v) {
        const auto res = std::to_chars(buf, buf + sizeof buf, v + 1);
        out.push_back(' ');
        out.append(buf, res.ptr);
    };
    const bool hasColor = !strands.color.empty();
    for (std::size_t v = 0; v < strands.numVertices(); ++v) {
        out += 'v';
        for (int c = 0; c < 3; ++c) putFloat(strands.positions[v][c]);
        if (hasColor) for (int c = 0; c < 3; ++c) putFloat(strands.color[v][c]);
        out += '\n';
    }
    for (std::size_t i = 0; i < strands.numStrands(); ++i) {
        if (style == ObjLineStyle::Edges) {
            for (std::size_t v = strands.begin(i); v + 1 < strands.end(i); ++v) {
                out += 'l';
                putIndex(v);
                putIndex(v + 1);
                out += '\n';
            }
        } else {
            out += 'l';
            for (std::size_t v = strands.begin(i); v < strands.end(i); ++v) putIndex(v);
            out += '\n';
        }
    }
    writeFileAtomic(path, out, where);
}

TriangleMesh readObjMesh(const std::string& path)
{
    const std::string where = "readObjMesh(" + path + ")";
    const std::vector<char> bytes = readFileBytes(path, where);
    TextScanner text(bytes, where);
    TriangleMesh mesh;
    std::vector<std::string_view> tok;
    std::vector<std::uint32_t> face;
    while (text.nextLine(tok)) {
        if (tok.empty()) continue;
        if (tok[0] == "v") {
            mesh.vertices.push_back(objPosition(text, tok, mesh.vertices.size(), where));
        } else if (tok[0] == "f") {
            if (tok.size() < 4) text.fail("an 'f' line needs at least 3 vertices, got " + std::to_string(tok.size() - 1));
            face.clear();
            for (std::size_t j = 1; j < tok.size(); ++j) face.push_back(objVertexIndex(text, tok[j], mesh.vertices.size()));
            for (std::size_t j = 1; j + 1 < face.size(); ++j) mesh.triangles.push_back({face[0], face[j], face[j + 1]});
        }
    }
    if (mesh.triangles.empty()) throw FormatError(where + ": the file has no faces ('f' lines)");
    return mesh;
}

} // namespace vdbhair
