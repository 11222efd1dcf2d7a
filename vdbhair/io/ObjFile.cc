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

/// @brief The state of reading an OBJ file, line by line: the vertices, every `l` element as
/// edges between consecutive vertices, and every free-form curve (`curv` ... `end`) evaluated to a
/// polyline as soon as it ends. One method a keyword.
class ObjReader
{
public:
    ObjReader(TextScanner& text, const std::string& where, const ReadOptions& opts)
        : mText(text), mWhere(where), mOpts(opts), mPoll(opts.interrupter, where) {}

    /// Step 1: every line, joined with its continuations, by its keyword.
    void readLines();
    /// Step 2: what the whole file must have, and the warnings for what was skipped.
    void checkAndWarn(ReadReport* report) const;
    /// Step 3: the strands: the chains of the `l` elements, then the curves in file order.
    StrandSet strands(ReadReport* report);

private:
    /// A line ending in a backslash continues on the next (the OBJ specification; Maya breaks
    /// long curv and parm lines so): the next lines' tokens are appended to @a tok.
    void joinContinuations(std::vector<std::string_view>& tok);
    /// `v x y z [w]` or `v x y z r g b`: a vertex, with its weight (rational curves) or colour.
    void vertex(const std::vector<std::string_view>& tok);
    /// `l i j k ...`: edges between consecutive vertices (`l i` alone: a one-vertex strand, unless an edge uses i).
    void lineElement(const std::vector<std::string_view>& tok);
    /// `cstype [rat] bspline|bezier|cardinal`: the type of the curves that follow.
    void curveType(const std::vector<std::string_view>& tok);
    /// `deg n`: the degree of the curves that follow.
    void degree(const std::vector<std::string_view>& tok);
    /// `curv u0 u1 i j ...`: a curve begins, on control points defined before it.
    void beginCurve(const std::vector<std::string_view>& tok);
    /// `parm u ...`: the knots of the curve being read.
    void curveParameters(const std::vector<std::string_view>& tok);
    /// `end`: the curve is evaluated to a polyline (FreeFormCurve.h).
    void endCurve();
    /// Curves on surfaces (trimming) and surfaces are not strands: skipped, up to their 'end'.
    void skipFreeForm(std::string_view key, std::vector<std::string_view>& tok);

    TextScanner& mText;
    const std::string& mWhere;
    const ReadOptions& mOpts;
    InterruptPoll mPoll;
    std::vector<std::string_view> mMore;

    std::vector<Vec3f> mVertices;
    std::vector<Vec3f> mColors;
    std::vector<double> mWeights;  // `v x y z w`: filled (with 1) only once a vertex has a weight
    bool mAnyColor = false;
    EdgeList mEdges;
    std::size_t mLineElements = 0, mIgnored = 0, mCurves = 0, mSkippedFreeForm = 0;
    std::size_t mSkippedFreeFormLine = 0;
    std::vector<std::uint32_t> mElement;

    // Free-form state: the attributes in force (cstype, deg) and the curve being read.
    FreeFormCurve mAttrs;
    bool mHaveCstype = false;
    bool mInCurve = false;
    std::size_t mCurveLine = 0;
    FreeFormCurve mCurve;
    std::vector<std::uint32_t> mCurveIndices;
    std::vector<Vec3f> mCurvePoints;
    std::vector<std::uint32_t> mCurveOffsets{0};
};

void ObjReader::readLines()
{
    std::vector<std::string_view> tok;
    while (mText.nextLine(tok)) {
        mPoll();
        joinContinuations(tok);
        if (tok.empty()) continue;
        const std::string_view key = tok[0];
        if (key == "v") vertex(tok);
        else if (key == "l") lineElement(tok);
        else if (key == "cstype") curveType(tok);
        else if (key == "deg") degree(tok);
        else if (key == "curv") beginCurve(tok);
        else if (key == "parm") curveParameters(tok);
        else if (key == "end") endCurve();
        else if (key == "curv2" || key == "surf") skipFreeForm(key, tok);
        else if (key[0] != '#') ++mIgnored;  // f, vn, vt, vp, o, g, s, usemtl, mtllib, trim, hole, ...
    }
}

void ObjReader::joinContinuations(std::vector<std::string_view>& tok)
{
    while (!tok.empty() && tok.back() == "\\" && mText.nextLine(mMore)) {
        tok.pop_back();
        tok.insert(tok.end(), mMore.begin(), mMore.end());
    }
    if (!tok.empty() && tok.back() == "\\") tok.pop_back();
}

void ObjReader::vertex(const std::vector<std::string_view>& tok)
{
    mVertices.push_back(objPosition(mText, tok, mVertices.size(), mWhere));
    Vec3f c(0.5f);
    if (tok.size() >= 7) {
        c = Vec3f(mText.toFloat(tok[4], "red"), mText.toFloat(tok[5], "green"), mText.toFloat(tok[6], "blue"));
        mAnyColor = true;
    } else if (tok.size() == 5) {
        const double w = mText.toDouble(tok[4], "weight");
        if (mWeights.empty() && w != 1.0) mWeights.assign(mVertices.size() - 1, 1.0);
        if (!mWeights.empty()) mWeights.push_back(w);
    }
    if (!mWeights.empty() && mWeights.size() < mVertices.size()) mWeights.push_back(1.0);
    mColors.push_back(c);
}

void ObjReader::lineElement(const std::vector<std::string_view>& tok)
{
    if (tok.size() < 2) mText.fail("an 'l' element needs at least one vertex index");
    ++mLineElements;
    mElement.clear();
    for (std::size_t j = 1; j < tok.size(); ++j) mElement.push_back(objVertexIndex(mText, tok[j], mVertices.size()));
    const std::uint32_t line = std::uint32_t(std::min<std::size_t>(mText.line(), 0xffffffffu));
    if (mElement.size() == 1) mEdges.singles.push_back({mElement[0], line});
    for (std::size_t j = 0; j + 1 < mElement.size(); ++j) {
        if (mElement[j] == mElement[j + 1]) { ++mEdges.selfEdges; continue; }
        mEdges.edges.push_back({std::min(mElement[j], mElement[j + 1]), std::max(mElement[j], mElement[j + 1]), line});
    }
}

void ObjReader::curveType(const std::vector<std::string_view>& tok)
{
    if (tok.size() < 2 || tok.size() > 3 || (tok.size() == 3 && tok[1] != "rat")) {
        mText.fail("'cstype' needs a type, optionally after 'rat': cstype [rat] bspline|bezier|cardinal");
    }
    const std::string_view type = tok.back();
    mAttrs.rational = tok.size() == 3;
    if (type == "bspline") mAttrs.basis = CurveBasis::BSpline;
    else if (type == "bezier") mAttrs.basis = CurveBasis::Bezier;
    else if (type == "cardinal") mAttrs.basis = CurveBasis::Cardinal;
    else if (type == "taylor" || type == "bmatrix") {
        throw UnsupportedError(mWhere + ": line " + std::to_string(mText.line()) + ": cstype " + std::string(type) +
                               " is not supported (bspline, bezier and cardinal curves are; convert the curves to one of them or to polylines)");
    } else {
        mText.fail("unknown cstype '" + std::string(type) + "' (the OBJ types are bspline, bezier, cardinal, taylor, bmatrix)");
    }
    mHaveCstype = true;
}

void ObjReader::degree(const std::vector<std::string_view>& tok)
{
    if (tok.size() < 2) mText.fail("'deg' needs a degree");
    const std::int64_t d = mText.toInt(tok[1], "degree");
    if (d < 1 || d > kMaxCurveDegree) {
        mText.fail("degree " + std::to_string(d) + " is outside 1.." + std::to_string(kMaxCurveDegree) + " (the degrees this reader evaluates)");
    }
    mAttrs.degree = int(d);
}

void ObjReader::beginCurve(const std::vector<std::string_view>& tok)
{
    if (mInCurve) mText.fail("'curv' before the 'end' of the curve begun on line " + std::to_string(mCurveLine));
    if (!mHaveCstype) mText.fail("'curv' before any 'cstype' (cstype bspline, bezier or cardinal)");
    if (tok.size() < 5) mText.fail("'curv' needs u0 u1 and at least two control point indices, got " + std::to_string(tok.size() - 1) + " values");
    mInCurve = true;
    mCurveLine = mText.line();
    mCurve = mAttrs;
    mCurve.u0 = mText.toDouble(tok[1], "curv u0");
    mCurve.u1 = mText.toDouble(tok[2], "curv u1");
    mCurveIndices.clear();
    for (std::size_t j = 3; j < tok.size(); ++j) mCurveIndices.push_back(objVertexIndex(mText, tok[j], mVertices.size()));
}

void ObjReader::curveParameters(const std::vector<std::string_view>& tok)
{
    if (!mInCurve) mText.fail("'parm' outside a curve (between 'curv' and 'end')");
    if (tok.size() < 2 || tok[1] != "u") mText.fail("a curve takes 'parm u' values only");
    mCurve.parms.clear();
    for (std::size_t j = 2; j < tok.size(); ++j) mCurve.parms.push_back(mText.toDouble(tok[j], "parm u"));
}

void ObjReader::endCurve()
{
    if (!mInCurve) mText.fail("'end' without a 'curv'");
    mInCurve = false;
    mCurve.points.clear();
    mCurve.weights.clear();
    for (const std::uint32_t v : mCurveIndices) {
        mCurve.points.emplace_back(mVertices[v].x(), mVertices[v].y(), mVertices[v].z());
        mCurve.weights.push_back(mWeights.empty() ? 1.0 : mWeights[v]);
    }
    if (std::string rule = flattenCurve(mCurve, mOpts.curveSamples, mCurvePoints); !rule.empty()) {
        throw FormatError(mWhere + ": line " + std::to_string(mCurveLine) + ": curve: " + rule);
    }
    mCurveOffsets.push_back(std::uint32_t(mCurvePoints.size()));
    ++mCurves;
}

void ObjReader::skipFreeForm(std::string_view key, std::vector<std::string_view>& tok)
{
    ++mSkippedFreeForm;
    if (!mSkippedFreeFormLine) mSkippedFreeFormLine = mText.line();
    if (mInCurve) mText.fail("'" + std::string(key) + "' before the 'end' of the curve begun on line " + std::to_string(mCurveLine));
    while (mText.nextLine(tok) && !(tok.size() == 1 && tok[0] == "end")) mPoll();
}

void ObjReader::checkAndWarn(ReadReport* report) const
{
    if (mInCurve) throw FormatError(mWhere + ": line " + std::to_string(mCurveLine) + ": the curve begun here has no 'end'");
    if (mLineElements == 0 && mCurves == 0) {
        throw FormatError(mWhere + ": no polylines: the file has no 'l' elements and no curves ('curv')" +
                          (mIgnored ? " (" + std::to_string(mIgnored) + " other lines, e.g. faces, were ignored)" : std::string()));
    }
    if (mIgnored && report) {
        report->warnings.push_back(mWhere + ": " + std::to_string(mIgnored) + " lines other than v and l (faces, normals, groups, ...) were ignored");
    }
    if (mSkippedFreeForm && report) {
        report->warnings.push_back(mWhere + ": skipped " + std::to_string(mSkippedFreeForm) + " curv2/surf element(s) (first on line " +
                                   std::to_string(mSkippedFreeFormLine) + "): curves on surfaces and surfaces are not strands");
    }
}

StrandSet ObjReader::strands(ReadReport* report)
{
    StrandSet out;
    if (mLineElements) {
        EdgeNaming naming;
        naming.vertexBase = 1;
        naming.place = "line";
        naming.places = "edges on lines";
        out = strandsFromEdges(mVertices, mAnyColor ? mColors : std::vector<Vec3f>{}, mEdges, naming, mWhere, mOpts, report);
    }
    if (mCurves) {
        // A curve's points have no colour of their own: the default grey where the lines have colours.
        for (std::size_t i = 0; i + 1 < mCurveOffsets.size(); ++i) {
            out.positions.insert(out.positions.end(), mCurvePoints.begin() + mCurveOffsets[i], mCurvePoints.begin() + mCurveOffsets[i + 1]);
            if (mAnyColor) out.color.resize(out.positions.size(), Vec3f(0.5f));
            out.offsets.push_back(std::uint32_t(out.positions.size()));
        }
    }
    return out;
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
    ObjReader reader(text, where, opts);
    reader.readLines();
    reader.checkAndWarn(report);
    return reader.strands(report);
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
