#include "UsdFile.h"

#include <vdbhair/Memory.h>
#include <vdbhair/Exceptions.h>
#include <vdbhair/Version.h>
#include <vdbhair/io/FileUtil.h>
#include <vdbhair/io/FreeFormCurve.h>
#include <vdbhair/io/UsdText.h>
#include <vdbhair/io/Xform.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>
#include <functional>
#include <map>

namespace vdbhair {

namespace {

using namespace usd;

/// A prim's own transform: its `xformOpOrder`'s ops, the last applied first (`!invert!` inverts
/// one; `!resetXformStack!` sets @a reset: the parents' transforms do not apply).
xform::Matrix localTransform(const PrimNode& node, bool& reset, const std::string& where, const std::function<void(const std::string&)>& warn)
{
    reset = false;
    xform::Matrix local = xform::kIdentity;
    const auto order = node.xformProps.find("xformOpOrder");
    if (order == node.xformProps.end() || !order->second.hasValue) return local;  // USD applies only ordered ops
    const std::string at = "prim \"" + node.name + "\" (line " + std::to_string(order->second.value.line) + ")";
    for (const std::string& entry : order->second.value.words) {
        if (entry == "!resetXformStack!") { reset = true; continue; }
        const bool inverse = entry.rfind("!invert!", 0) == 0;
        const std::string name = inverse ? entry.substr(8) : entry;
        const auto op = node.xformProps.find(name);
        if (op == node.xformProps.end() || !op->second.hasValue) {
            warn(at + ": xformOpOrder names \"" + name + "\", which has no value; that op is not applied");
            continue;
        }
        const std::size_t colon = name.find(':', 8);
        const std::string type = name.size() > 8 ? name.substr(8, colon == std::string::npos ? std::string::npos : colon - 8) : std::string();
        xform::Matrix m;
        if (std::string rule = xform::usdOp(type, op->second.value.numbers, m); !rule.empty()) {
            throw FormatError(where + ": line " + std::to_string(op->second.value.line) + ": " + at + ": " + name + ": " + rule);
        }
        if (inverse && !xform::invert(m, m)) {
            throw FormatError(where + ": line " + std::to_string(op->second.value.line) + ": " + at + ": !invert!" + name + " is not invertible");
        }
        local = xform::multiply(m, local);
    }
    return local;
}

/// The transform from a prim's space to the stage's: its own, then its parents' up the tree.
xform::Matrix worldTransform(const UsdDocument& doc, std::size_t node, const std::string& where, const std::function<void(const std::string&)>& warn)
{
    xform::Matrix world = xform::kIdentity;
    for (std::size_t n = node; n != kNoParent; n = doc.nodes[n].parent) {
        bool reset = false;
        world = xform::multiply(world, localTransform(doc.nodes[n], reset, where, warn));
        if (reset) break;
    }
    return world;
}

/// A primvar's values as stored: per curve, per control point, or per segment end (varying).
enum class Interp { Constant, Uniform, Vertex, Varying };

struct Primvar
{
    Interp interp = Interp::Constant;
    std::size_t arity = 1;
    std::vector<float> values;
};

using Warn = std::function<void(const std::string&)>;

/// One BasisCurves prim being read: where it is, its properties, and what the steps below find.
struct CurvesReading
{
    CurvesReading(const CurvesPrim& p, std::string file) : prim(p), where(std::move(file)), at("prim \"" + p.name + "\" (line " + std::to_string(p.line) + ")") {}

    const CurvesPrim& prim;
    std::string where, at;  ///< the file's label; the prim and its line
    // curveKind()
    bool linear = true;
    CubicBasis basis = CubicBasis::Bezier;
    CurveWrap wrap = CurveWrap::Nonperiodic;
    std::string basisName, wrapName;
    // curveCounts()
    std::vector<std::size_t> counts;
    const std::vector<double>* points = nullptr;  ///< x, y, z per control point
    std::size_t numPoints = 0, numVarying = 0;
    // primvars()
    Primvar widths, colors, opacity;
    StrandDefaults defaults;
    bool uniformWidth = false;

    const Property* find(const char* name) const
    {
        const auto it = prim.props.find(name);
        return it != prim.props.end() && it->second.hasValue ? &it->second : nullptr;
    }
    std::string token(const char* name, const char* fallback) const
    {
        const Property* t = find(name);
        return t && !t->value.words.empty() ? t->value.words[0] : std::string(fallback);
    }
    [[noreturn]] void fail(std::size_t line, const std::string& what) const
    {
        throw FormatError(where + ": " + (line ? "line " + std::to_string(line) + ": " : std::string()) + at + ": " + what);
    }
};

/// `type`, `basis` and `wrap`, with USD's fallbacks (cubic Bezier curves, not periodic).
void curveKind(CurvesReading& r, const Warn& warn)
{
    const std::string type = r.token("type", "cubic");
    r.basisName = r.token("basis", "bezier");
    r.wrapName = r.token("wrap", "nonperiodic");
    if (type != "linear" && type != "cubic") r.fail(0, "type \"" + type + "\"; BasisCurves are linear or cubic");
    if (r.wrapName != "nonperiodic" && r.wrapName != "periodic" && r.wrapName != "pinned") {
        r.fail(0, "wrap \"" + r.wrapName + "\"; expected nonperiodic, periodic or pinned");
    }
    r.wrap = r.wrapName == "periodic" ? CurveWrap::Periodic : r.wrapName == "pinned" ? CurveWrap::Pinned : CurveWrap::Nonperiodic;
    r.linear = type == "linear";
    if (r.linear) return;
    if (r.basisName == "bspline") r.basis = CubicBasis::BSpline;
    else if (r.basisName == "catmullRom") r.basis = CubicBasis::CatmullRom;
    else if (r.basisName != "bezier") {
        warn(r.at + ": cubic basis \"" + r.basisName + "\" (deprecated in USD) is not evaluated; its control points are read as a polyline");
        r.linear = true;
    }
}

/// `curveVertexCounts` against `points`; the values a varying primvar has.
void curveCounts(CurvesReading& r, const Warn& warn, InterruptPoll& poll)
{
    const Property* counts = r.find("curveVertexCounts");
    const Property* points = r.find("points");
    if (!counts) r.fail(0, "BasisCurves without curveVertexCounts");
    if (!points) r.fail(0, "BasisCurves without points");
    const std::vector<double>& n = counts->value.numbers;
    const std::vector<double>& p = points->value.numbers;
    if (p.size() % 3 != 0 || (points->value.array && points->value.elements * 3 != p.size())) {
        r.fail(points->value.line, "points must be (x, y, z) triples");
    }
    r.points = &p;
    r.numPoints = p.size() / 3;
    std::uint64_t sum = 0;
    r.counts.reserve(n.size());
    for (std::size_t i = 0; i < n.size(); ++i) {
        poll();
        if (!(n[i] >= 0.0) || n[i] != std::floor(n[i]) || n[i] > 4294967295.0) {
            r.fail(counts->value.line, "curveVertexCounts[" + std::to_string(i) + "] is " + std::to_string(n[i]) + "; counts must be whole numbers of at least 0");
        }
        r.counts.push_back(std::size_t(n[i]));
        sum += std::uint64_t(n[i]);
    }
    if (sum != r.numPoints) {
        r.fail(counts->value.line, "curveVertexCounts add up to " + std::to_string(sum) + " but there are " + std::to_string(r.numPoints) + " points");
    }
    if (!r.linear && !r.find("type") && !r.find("basis")) {
        // USD's fallback is cubic Bezier; curves whose counts cannot be Bezier curves were meant
        // as polylines (a writer that left the type out).
        const bool bezier = std::all_of(r.counts.begin(), r.counts.end(), [](std::size_t c) { return c >= 4 && (c - 1) % 3 == 0; });
        if (!bezier) {
            warn(r.at + ": type is not authored and its curves do not fit USD's fallback (cubic Bezier: 3 k + 1 points); read as linear");
            r.linear = true;
        }
    }
    r.numVarying = 0;
    for (std::size_t c : r.counts) r.numVarying += r.linear ? c : cubicVaryingCount(r.basis, r.wrap, c);
}

/// A primvar's values with their interpolation: false when absent; a constant goes into @a constant.
bool readPrimvar(const CurvesReading& r, const char* name, std::size_t arity, Primvar& pv, float* constant)
{
    pv = Primvar{};
    pv.arity = arity;
    const Property* prop = r.find(name);
    if (!prop) return false;
    const std::vector<double>& v = prop->value.numbers;
    // The interpolation: the metadata, else an attribute NAME:interpolation (older writers), else
    // USD's fallback (vertex for widths; constant for primvars and for one width).
    std::string interp = prop->interpolation;
    if (const Property* i = interp.empty() ? r.find((std::string(name) + ":interpolation").c_str()) : nullptr; i && !i->value.words.empty()) {
        interp = i->value.words[0];
    }
    if (interp.empty()) interp = std::strcmp(name, "widths") == 0 && v.size() != 1 ? "vertex" : "constant";
    auto need = [&](std::uint64_t count, const char* per) {
        if (v.size() != arity * count) {
            r.fail(prop->value.line, interp + " " + name + " needs one value per " + per + " (" + std::to_string(count) + "), got " + std::to_string(v.size() / arity));
        }
    };
    if (interp == "constant") {
        if (v.size() != arity) r.fail(prop->value.line, "constant " + std::string(name) + " needs " + std::to_string(arity) + " number(s), got " + std::to_string(v.size()));
        for (std::size_t c = 0; c < arity; ++c) constant[c] = float(v[c]);
        return true;
    }
    if (interp == "uniform") { need(r.counts.size(), "curve"); pv.interp = Interp::Uniform; }
    else if (interp == "vertex") { need(r.numPoints, "point"); pv.interp = Interp::Vertex; }
    else if (interp == "varying") { need(r.numVarying, r.linear ? "point" : "segment end"); pv.interp = Interp::Varying; }
    else r.fail(prop->value.line, std::string(name) + " has interpolation \"" + interp + "\"; expected constant, uniform, vertex or varying");
    pv.values.assign(v.begin(), v.end());
    return true;
}

/// Widths, colour and opacity, and the defaults (cyHair's header) where the file has vdbhair's
/// own record of them.
void primvars(CurvesReading& r)
{
    StrandDefaults& defaults = r.defaults;
    float opacityConstant = 1.f - defaults.transparency;
    const bool constantWidth = readPrimvar(r, "widths", 1, r.widths, &defaults.thickness) && r.widths.values.empty();
    const bool constantColor = readPrimvar(r, "primvars:displayColor", 3, r.colors, &defaults.color[0]) && r.colors.values.empty();
    const bool constantOpacity = readPrimvar(r, "primvars:displayOpacity", 1, r.opacity, &opacityConstant) && r.opacity.values.empty();
    if (constantOpacity) defaults.transparency = 1.f - opacityConstant;
    // A per-vertex array of one value that writeUsda() wrote once (vdbhair_uniform_*): the
    // array again, so .hair -> .usda -> .hair keeps it.
    auto flag = [&](const char* name) {
        const Property* f = r.find(name);
        return f && !f->value.words.empty() && f->value.words[0] == "true";
    };
    r.uniformWidth = constantWidth && flag("vdbhair_uniform_thickness");
    const bool displayWidth = constantWidth && flag("vdbhair_display_width");
    const bool uniformColor = constantColor && flag("vdbhair_uniform_color");
    const bool uniformOpacity = constantOpacity && flag("vdbhair_uniform_transparency");
    auto asUniform = [&](Primvar& pv, const float* value) {  // one value for every curve
        pv.interp = Interp::Uniform;
        pv.values.resize(pv.arity * r.counts.size());
        for (std::size_t i = 0; i < r.counts.size(); ++i) std::copy(value, value + pv.arity, pv.values.begin() + std::ptrdiff_t(pv.arity * i));
    };
    if (r.uniformWidth) asUniform(r.widths, &defaults.thickness);
    if (uniformColor) asUniform(r.colors, &defaults.color[0]);
    if (uniformOpacity) asUniform(r.opacity, &opacityConstant);
    // vdbhair's own record of the defaults (exact, and kept when the arrays are per vertex); a
    // constant primvar that is not such an array is what the file says for every vertex, and
    // wins (a width given to the writer).
    if (const Property* d = r.find("vdbhair_default_thickness"); d && d->value.numbers.size() == 1 && (!constantWidth || r.uniformWidth || displayWidth)) {
        defaults.thickness = float(d->value.numbers[0]);
    }
    if (const Property* d = r.find("vdbhair_default_transparency"); d && d->value.numbers.size() == 1) {
        // Exact where the constant opacity says the same (1 - t rounds in float).
        const float t = float(d->value.numbers[0]);
        if (!constantOpacity || uniformOpacity || 1.f - t == opacityConstant) defaults.transparency = t;
    }
    if (const Property* d = r.find("vdbhair_default_color"); d && d->value.numbers.size() == 3 && (!constantColor || uniformColor)) {
        defaults.color = Vec3f(float(d->value.numbers[0]), float(d->value.numbers[1]), float(d->value.numbers[2]));
    }
}

/// The prim's curves as polylines in the stage's space (@a world), with their attributes, into
/// @a part; strands the filter drops are skipped.
void appendCurves(const CurvesReading& r, const xform::Matrix& world, std::size_t curveSamples, ShortStrandFilter& filter,
                  std::size_t& strandIndex, StrandSet& part)
{
    const bool transformed = world != xform::kIdentity;
    const float widthScale = transformed ? float(xform::lengthScale(world)) : 1.f;
    const std::vector<double>& p = *r.points;
    std::vector<Vec3f> controls, poly;
    std::size_t v0 = 0, vv0 = 0;
    for (std::size_t i = 0; i < r.counts.size(); ++i) {
        const std::size_t cnt = r.counts[i];
        controls.clear();
        for (std::size_t k = v0; k < v0 + cnt; ++k) {
            const Vec3f q(static_cast<float>(p[3 * k]), static_cast<float>(p[3 * k + 1]), static_cast<float>(p[3 * k + 2]));
            checkFinite(q, k, r.where, r.at);
            controls.push_back(q);
            if (transformed) {
                controls.back() = xform::transformPoint(world, q);
                checkFinite(controls.back(), k, r.where, r.at + " after its transform");
            }
        }
        if (r.linear) {
            poly = controls;
            if (r.wrap == CurveWrap::Periodic && cnt >= 2) poly.push_back(controls.front());
        } else {
            poly.clear();
            const FreeFormCurve curve = cubicCurve(r.basis, r.wrap, controls.data(), cnt);
            if (std::string rule = flattenCurve(curve, curveSamples, poly); !rule.empty()) {
                r.fail(0, "curve " + std::to_string(i) + " (cubic " + r.basisName + ", " + r.wrapName + "): " + rule);
            }
        }
        const std::size_t nv = r.linear ? cnt : cubicVaryingCount(r.basis, r.wrap, cnt);
        // A primvar at polyline point k: per curve, or between the values along the curve.
        auto valueAt = [&](const Primvar& pv, std::size_t k, std::size_t c) -> float {
            const std::size_t at0 = pv.interp == Interp::Uniform ? i : pv.interp == Interp::Vertex ? v0 : vv0;
            const std::size_t m = pv.interp == Interp::Uniform ? 1 : pv.interp == Interp::Vertex ? cnt : nv;
            if (m == 0) return 0.f;
            if (r.linear && m > 1) return pv.values[pv.arity * (at0 + (k < m ? k : 0)) + c];
            const CurvePosition pos = positionAlong(k, poly.size(), m);
            return (1.f - pos.f) * pv.values[pv.arity * (at0 + pos.i0) + c] + pos.f * pv.values[pv.arity * (at0 + pos.i1) + c];
        };
        if (filter.keep(strandIndex++, poly.size(), r.at + ", curve " + std::to_string(i))) {
            for (std::size_t k = 0; k < poly.size(); ++k) {
                part.positions.push_back(poly[k]);
                if (!r.widths.values.empty()) part.thickness.push_back(valueAt(r.widths, k, 0) * widthScale);
                if (!r.colors.values.empty()) part.color.emplace_back(valueAt(r.colors, k, 0), valueAt(r.colors, k, 1), valueAt(r.colors, k, 2));
                if (!r.opacity.values.empty()) part.transparency.push_back(1.f - valueAt(r.opacity, k, 0));
            }
            part.offsets.push_back(std::uint32_t(part.positions.size()));
        }
        v0 += cnt;
        vv0 += nv;
    }
}

} // namespace

StrandSet readUsda(const std::string& path, const ReadOptions& opts, ReadReport* report)
{
    const std::string where = "readUsda(" + path + ")";
    const std::vector<char> bytes = readFileBytes(path, where, opts.interrupter);
    const UsdDocument doc = parseUsda(bytes, where);
    if (doc.curves.empty()) {
        throw FormatError(where + ": no strands: the file has no 'def BasisCurves' prim");
    }
    const Warn warn = [&](const std::string& w) { if (report) report->warnings.push_back(where + ": " + w); };
    // render's up axis: the command line's --up, Python's up= (not a declared parameter).
    if (doc.upAxis == "Z") warn("the stage's upAxis is Z; coordinates are kept as they are (render with " + spelled(ParamName{"--up", "up"}, opts.spelling) + " set to z)");
    if (doc.timeSampled) warn(std::to_string(doc.timeSampled) + " time-sampled attribute(s) were read at their first sample (an animation's first frame)");

    StrandSet out;
    ShortStrandFilter filter(opts, report, where);
    std::size_t strandIndex = 0;
    bool first = true;
    InterruptPoll poll(opts.interrupter, where);
    for (const CurvesPrim& prim : doc.curves) {
        poll();
        CurvesReading r(prim, where);
        curveKind(r, warn);
        curveCounts(r, warn, poll);
        r.defaults = out.defaults;
        primvars(r);
        // The prim's transform to the stage's space (its xformOps and its parents'); widths scale
        // with it.
        const xform::Matrix world = worldTransform(doc, prim.node, where, warn);
        if (world != xform::kIdentity) r.defaults.thickness *= float(xform::lengthScale(world));
        if (first) out.defaults = r.defaults;
        first = false;
        // Strands, with the attributes where this prim has them (defaults elsewhere).
        StrandSet part;
        part.defaults = out.defaults;
        appendCurves(r, world, opts.curveSamples, filter, strandIndex, part);
        if (out.empty()) {
            out = std::move(part);
        } else {
            out.append(part);
        }
    }
    filter.finish();
    // The stage's space, carried (not applied): USD's fallbacks are centimetres and +Y up.
    out.metersPerUnit = doc.metersPerUnit > 0.0 ? doc.metersPerUnit : 0.01;
    out.upAxis = doc.upAxis == "Z" ? 'Z' : 'Y';
    return out;
}

float automaticUsdWidth(const StrandSet& strands)
{
    const BBox box = computeBBox(strands);
    const Vec3f d = box.max - box.min;
    const float diagonal = std::sqrt(d.x() * d.x() + d.y() * d.y() + d.z() * d.z());
    return diagonal > 0.f ? kAutomaticWidthPerDiagonal * diagonal : 1.f;
}

void writeUsda(const std::string& path, const StrandSet& strands, const UsdWriteOptions& opts)
{
    const std::string where = "writeUsda(" + path + ")";
    if (strands.empty()) throw ValueError(where + ": the hairstyle has no strands; there is nothing to write");
    if (!opts.upAxis.empty() && opts.upAxis != "Y" && opts.upAxis != "Z") throw ValueError(where + ": up axis '" + opts.upAxis + "' must be Y or Z (USD's choices)");
    const std::string upAxis = !opts.upAxis.empty() ? opts.upAxis : strands.upAxis == 'Z' ? "Z" : "Y";
    if (!(opts.metersPerUnit >= 0.0) || !std::isfinite(opts.metersPerUnit)) {
        throw ValueError(where + ": metersPerUnit " + std::to_string(opts.metersPerUnit) + " must be positive and finite (0: the strands' own, else 0.01)");
    }
    if (!(opts.width >= 0.0f) || !std::isfinite(opts.width)) {
        throw ValueError(where + ": width " + std::to_string(opts.width) + " must be positive and finite (0: automatic)");
    }
    const double metersPerUnit = opts.metersPerUnit > 0.0 ? opts.metersPerUnit : strands.metersPerUnit > 0.0 ? strands.metersPerUnit : 0.01;
    const std::size_t nV = strands.numVertices(), nS = strands.numStrands();
    std::string out;
    reserveHugePages(out, 64 * nV + 8 * nS + 1024);
    char buf[64];
    auto num = [&](double v, bool isFloat = true) {
        const auto res = isFloat ? std::to_chars(buf, buf + sizeof buf, float(v)) : std::to_chars(buf, buf + sizeof buf, v);
        out.append(buf, res.ptr);
    };
    auto vec3 = [&](const Vec3f& v) {
        out += '(';
        num(v.x()); out += ", "; num(v.y()); out += ", "; num(v.z());
        out += ')';
    };
    out += "#usda 1.0\n(\n    defaultPrim = \"hair\"\n    doc = \"";
    out += creatorString();
    out += ": " + std::to_string(nS) + " strands, " + std::to_string(nV) + " vertices, root to tip\"\n    metersPerUnit = ";
    num(metersPerUnit, false);
    out += "\n    upAxis = \"" + upAxis + "\"\n)\n\n";
    out += "def BasisCurves \"hair\"\n{\n";
    out += "    uniform token type = \"linear\"\n";
    out += "    uniform token wrap = \"nonperiodic\"\n";
    out += "    int[] curveVertexCounts = [";
    for (std::size_t i = 0; i < nS; ++i) {
        if (i) out += ", ";
        out += std::to_string(strands.size(i));
    }
    out += "]\n    point3f[] points = [";
    for (std::size_t v = 0; v < nV; ++v) {
        if (v) out += ", ";
        vec3(strands.positions[v]);
    }
    out += "]\n";
    // Widths, colour and opacity: per vertex where the set has them and they vary; one value with
    // "constant" interpolation where they do not (a .hair file's colour array of one colour, the
    // defaults where the set has no array).
    auto uniformValue = [](const auto& values) {
        return std::all_of(values.begin(), values.end(), [&](const auto& v) { return v == values.front(); });
    };
    std::string uniformFlags;  // vdbhair_uniform_*: which constants stand for a per-vertex array
    auto primvar = [&](const char* decl, const auto& values, const auto& constant, auto write, const char* flag) {
        const bool constantValue = values.empty() || uniformValue(values);
        if (!values.empty() && constantValue) uniformFlags += std::string("    custom bool vdbhair_uniform_") + flag + " = true\n";
        out += std::string("    ") + decl + " = [";
        if (constantValue) write(values.empty() ? constant : values.front());
        else for (std::size_t v = 0; v < values.size(); ++v) { if (v) out += ", "; write(values[v]); }
        out += std::string("] (\n        interpolation = \"") + (constantValue ? "constant" : "vertex") + "\"\n    )\n";
    };
    auto writeFloat = [&](float x) { num(x); };
    auto writeVec3 = [&](const Vec3f& v) { vec3(v); };
    // Curves without thickness: --width, else the file's declared default, else automatic (a
    // thousandth of the bounding box's diagonal; writing 1 drew hair in metres as a blob).
    float constantWidth = strands.defaults.thickness;
    if (strands.thickness.empty()) {
        if (opts.width > 0.f) constantWidth = opts.width;
        else if (strands.defaults.thickness == StrandDefaults{}.thickness) constantWidth = automaticUsdWidth(strands);
    }
    // A width chosen for display (not the strands' thickness): vdbhair reads the defaults back
    // exactly, other tools draw the width.
    if (constantWidth != strands.defaults.thickness) uniformFlags += "    custom bool vdbhair_display_width = true\n";
    primvar("float[] widths", strands.thickness, constantWidth, writeFloat, "thickness");
    primvar("color3f[] primvars:displayColor", strands.color, strands.defaults.color, writeVec3, "color");
    std::vector<float> opacity(strands.transparency.size());
    for (std::size_t v = 0; v < opacity.size(); ++v) opacity[v] = 1.f - strands.transparency[v];
    primvar("float[] primvars:displayOpacity", opacity, 1.f - strands.defaults.transparency, writeFloat, "transparency");
    // The defaults themselves (cyHair's header), exactly, whether or not the arrays are per vertex.
    out += "    custom float vdbhair_default_thickness = ";
    num(strands.defaults.thickness);
    out += "\n    custom float vdbhair_default_transparency = ";
    num(strands.defaults.transparency);
    out += "\n    custom color3f vdbhair_default_color = ";
    vec3(strands.defaults.color);
    out += "\n" + uniformFlags;
    const BBox box = computeBBox(strands);
    out += "    float3[] extent = [";
    vec3(box.min);
    out += ", ";
    vec3(box.max);
    out += "]\n}\n";
    writeFileAtomic(path, out, where);
}

} // namespace vdbhair
