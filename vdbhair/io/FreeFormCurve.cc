#include "FreeFormCurve.h"

#include <vdbhair/Format.h>

#include <algorithm>
#include <array>
#include <cmath>

namespace vdbhair {

namespace {

using Vec4 = std::array<double, 4>;  // (w x, w y, w z, w): homogeneous, for rational curves

/// A B-spline in homogeneous form: #N control points, #N + degree + 1 knots, domain [uMin, uMax].
struct BSpline
{
    int degree = 3;
    std::vector<Vec4> cw;
    std::vector<double> knots;
    double uMin = 0.0, uMax = 1.0;
};

std::string num(double v) { return formatNumber(v); }

/// The span k (degree <= k < #N) with knots[k] <= u < knots[k+1]; the last non-empty span at the domain's end.
std::size_t findSpan(const BSpline& s, double u)
{
    const std::size_t n = s.cw.size(), p = std::size_t(s.degree);
    if (u >= s.knots[n]) {
        std::size_t k = n - 1;
        while (k > p && !(s.knots[k] < s.knots[k + 1])) --k;
        return k;
    }
    // The first knot above u, over [p+1, n]: the span is the one before it.
    const auto it = std::upper_bound(s.knots.begin() + std::ptrdiff_t(p) + 1, s.knots.begin() + std::ptrdiff_t(n) + 1, u);
    return std::size_t(it - s.knots.begin()) - 1;
}

/// de Boor's algorithm (Piegl and Tiller, The NURBS Book, A2.2 and Eq. 4.2 for the rational case).
Vec3d evaluate(const BSpline& s, double u, std::vector<Vec4>& d)
{
    const std::size_t p = std::size_t(s.degree), k = findSpan(s, u);
    d.assign(s.cw.begin() + std::ptrdiff_t(k - p), s.cw.begin() + std::ptrdiff_t(k + 1));
    for (std::size_t r = 1; r <= p; ++r) {
        for (std::size_t j = p; j >= r; --j) {
            const double lo = s.knots[j + k - p], hi = s.knots[j + 1 + k - r];
            const double a = hi > lo ? (u - lo) / (hi - lo) : 0.0;
            for (int c = 0; c < 4; ++c) d[j][std::size_t(c)] = (1.0 - a) * d[j - 1][std::size_t(c)] + a * d[j][std::size_t(c)];
        }
    }
    const Vec4& h = d[p];
    return Vec3d(h[0] / h[3], h[1] / h[3], h[2] / h[3]);
}

/// The distance from @a q to the segment [a, b].
double segmentDistance(const Vec3d& q, const Vec3d& a, const Vec3d& b)
{
    const Vec3d ab = b - a;
    const double len2 = ab.lengthSqr();
    const double t = len2 > 0.0 ? std::clamp((q - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
    return (q - (a + t * ab)).length();
}

/// Uniform parameters over [u0, u1]: @a count values, or 0..1 when the range is empty.
std::vector<double> uniform(double u0, double u1, std::size_t count)
{
    if (!(u0 < u1)) { u0 = 0.0; u1 = 1.0; }
    std::vector<double> v(count);
    for (std::size_t i = 0; i < count; ++i) v[i] = count > 1 ? u0 + (u1 - u0) * double(i) / double(count - 1) : u0;
    return v;
}

/// Bezier (or cardinal) segments joined at @a parms (#K+1 values, increasing) as a B-spline:
/// each interior knot repeated degree times, the ends degree + 1 times.
std::string bezierKnots(const std::vector<double>& parms, int degree, std::vector<double>& knots)
{
    for (std::size_t i = 0; i + 1 < parms.size(); ++i) {
        if (!(parms[i] < parms[i + 1])) {
            return "parm u value " + std::to_string(i + 1) + " (" + num(parms[i + 1]) + ") is not above the one before (" +
                   num(parms[i]) + "); segment parameters must increase";
        }
    }
    knots.clear();
    for (std::size_t i = 0; i < parms.size(); ++i) {
        const int times = (i == 0 || i + 1 == parms.size()) ? degree + 1 : degree;
        knots.insert(knots.end(), std::size_t(times), parms[i]);
    }
    return {};
}

/// @a curve as a B-spline, or the rule it breaks.
std::string toBSpline(const FreeFormCurve& curve, BSpline& s)
{
    const std::size_t n = curve.points.size();
    const int p = curve.degree;
    if (p < 1 || p > kMaxCurveDegree) return "degree " + std::to_string(p) + " is outside 1.." + std::to_string(kMaxCurveDegree);
    if (!(std::isfinite(curve.u0) && std::isfinite(curve.u1)) || curve.u0 == curve.u1) {
        return "the parameter range " + num(curve.u0) + " .. " + num(curve.u1) + " must be finite and not empty";
    }
    for (double k : curve.parms) {
        if (!std::isfinite(k)) return "parm u value " + num(k) + " is not finite";
    }
    const double lo = std::min(curve.u0, curve.u1), hi = std::max(curve.u0, curve.u1);
    s.degree = p;
    std::vector<Vec3d> points = curve.points;
    std::vector<double> weights = curve.weights;
    if (curve.rational) {
        for (std::size_t i = 0; i < n; ++i) {
            if (!(weights[i] > 0.0) || !std::isfinite(weights[i])) {
                return "control point " + std::to_string(i + 1) + " has weight " + num(weights[i]) + "; a rational curve needs weights above 0";
            }
        }
    } else {
        weights.assign(n, 1.0);
    }
    switch (curve.basis) {
    case CurveBasis::BSpline: {
        if (n < std::size_t(p) + 1) {
            return "degree " + std::to_string(p) + " needs at least " + std::to_string(p + 1) + " control points, got " + std::to_string(n);
        }
        if (curve.parms.empty()) {
            // Uniform and clamped over [u0, u1]: the curve starts and ends at its end points.
            const std::vector<double> inner = uniform(lo, hi, n - std::size_t(p) + 1);
            s.knots.assign(std::size_t(p), inner.front());
            s.knots.insert(s.knots.end(), inner.begin(), inner.end());
            s.knots.insert(s.knots.end(), std::size_t(p), inner.back());
        } else {
            if (curve.parms.size() != n + std::size_t(p) + 1) {
                return "the knot vector (parm u) has " + std::to_string(curve.parms.size()) + " values; " + std::to_string(n) +
                       " control points of degree " + std::to_string(p) + " need " + std::to_string(n + std::size_t(p) + 1);
            }
            for (std::size_t i = 0; i + 1 < curve.parms.size(); ++i) {
                if (curve.parms[i + 1] < curve.parms[i]) {
                    return "knot " + std::to_string(i + 2) + " (" + num(curve.parms[i + 1]) + ") is below knot " + std::to_string(i + 1) +
                           " (" + num(curve.parms[i]) + "); knots must not decrease";
                }
            }
            s.knots = curve.parms;
        }
        break;
    }
    case CurveBasis::Bezier: {
        if (n < std::size_t(p) + 1 || (n - 1) % std::size_t(p) != 0) {
            return "a Bezier curve of degree " + std::to_string(p) + " needs " + std::to_string(p) + " k + 1 control points (k segments), got " +
                   std::to_string(n);
        }
        const std::size_t segments = (n - 1) / std::size_t(p);
        std::vector<double> parms = curve.parms.empty() ? uniform(lo, hi, segments + 1) : curve.parms;
        if (parms.size() != segments + 1) {
            return "parm u has " + std::to_string(parms.size()) + " values; " + std::to_string(segments) + " Bezier segment(s) need " +
                   std::to_string(segments + 1);
        }
        if (std::string e = bezierKnots(parms, p, s.knots); !e.empty()) return e;
        break;
    }
    case CurveBasis::Cardinal: {
        // Catmull-Rom (tension 1/2): the segment from P[i+1] to P[i+2] is the cubic Bezier
        // P[i+1], P[i+1] + (P[i+2] - P[i]) / 6, P[i+2] - (P[i+3] - P[i+1]) / 6, P[i+2].
        if (p != 3) return "a cardinal curve has degree 3, not " + std::to_string(p);
        if (curve.rational) return "a rational cardinal curve is not supported (rat applies to bspline and bezier)";
        if (n < 4) return "a cardinal curve needs at least 4 control points, got " + std::to_string(n);
        const std::size_t segments = n - 3;
        std::vector<double> parms = curve.parms.empty() ? uniform(lo, hi, segments + 1) : curve.parms;
        if (parms.size() != segments + 1) {
            return "parm u has " + std::to_string(parms.size()) + " values; " + std::to_string(segments) + " cardinal segment(s) need " +
                   std::to_string(segments + 1);
        }
        if (std::string e = bezierKnots(parms, 3, s.knots); !e.empty()) return e;
        std::vector<Vec3d> bez{points[1]};
        for (std::size_t i = 0; i < segments; ++i) {
            bez.push_back(points[i + 1] + (points[i + 2] - points[i]) / 6.0);
            bez.push_back(points[i + 2] - (points[i + 3] - points[i + 1]) / 6.0);
            bez.push_back(points[i + 2]);
        }
        points = std::move(bez);
        weights.assign(points.size(), 1.0);
        break;
    }
    }
    s.cw.resize(points.size());
    for (std::size_t i = 0; i < points.size(); ++i) {
        s.cw[i] = {weights[i] * points[i].x(), weights[i] * points[i].y(), weights[i] * points[i].z(), weights[i]};
    }
    // The range evaluated: the curv line's, within the knot vector's domain (Blender writes
    // "curv 0.0 1.0" for unclamped knot vectors whose domain is smaller).
    const std::size_t nc = s.cw.size();
    const double a = s.knots[std::size_t(p)], b = s.knots[nc];
    if (!(a < b)) return "the knot vector's domain [" + num(a) + ", " + num(b) + "] is empty (knot " + std::to_string(p + 1) + " to knot " + std::to_string(nc + 1) + ")";
    s.uMin = std::max(lo, a);
    s.uMax = std::min(hi, b);
    if (!(s.uMin < s.uMax)) {
        return "the parameter range " + num(curve.u0) + " .. " + num(curve.u1) + " lies outside the knot vector's domain [" + num(a) + ", " + num(b) + "]";
    }
    return {};
}

/// Append the points of [a, b] after a (b included), bisecting while the piece is not flat enough.
void flattenPiece(const BSpline& s, double a, const Vec3d& pa, double b, const Vec3d& pb, double lengthTol, int depth,
                  std::vector<Vec4>& scratch, std::vector<Vec3d>& out)
{
    constexpr int kMaxDepth = 10;
    const double chord = (pb - pa).length();
    const double tol = std::min(0.05 * chord, lengthTol);
    const Vec3d q1 = evaluate(s, a + 0.25 * (b - a), scratch);
    const Vec3d qm = evaluate(s, 0.5 * (a + b), scratch);
    const Vec3d q3 = evaluate(s, a + 0.75 * (b - a), scratch);
    const double dev = std::max({segmentDistance(q1, pa, pb), segmentDistance(qm, pa, pb), segmentDistance(q3, pa, pb)});
    if (dev <= tol || depth >= kMaxDepth) {
        out.push_back(pb);
        return;
    }
    const double m = 0.5 * (a + b);
    flattenPiece(s, a, pa, m, qm, lengthTol, depth + 1, scratch, out);
    flattenPiece(s, m, qm, b, pb, lengthTol, depth + 1, scratch, out);
}

} // namespace

std::string flattenCurve(const FreeFormCurve& curve, std::size_t samples, std::vector<Vec3f>& out)
{
    if (curve.weights.size() != curve.points.size()) return "internal: one weight per control point";
    if (samples == 1) return "a sample count of 1 makes no strand; give 2 or more, or 0 for the automatic count";
    BSpline s;
    if (std::string e = toBSpline(curve, s); !e.empty()) return e;
    std::vector<Vec4> scratch;
    std::vector<Vec3d> pts;
    if (samples >= 2) {
        pts.reserve(samples);
        for (std::size_t i = 0; i < samples; ++i) {
            const double u = i + 1 == samples ? s.uMax : s.uMin + (s.uMax - s.uMin) * double(i) / double(samples - 1);
            pts.push_back(evaluate(s, u, scratch));
        }
    } else {
        // The spans' ends within [uMin, uMax], then the curve's length from 8 chords a span.
        std::vector<double> breaks{s.uMin};
        for (double k : s.knots) if (k > breaks.back() && k < s.uMax) breaks.push_back(k);
        breaks.push_back(s.uMax);
        double length = 0.0;
        for (std::size_t i = 0; i + 1 < breaks.size(); ++i) {
            Vec3d prev = evaluate(s, breaks[i], scratch);
            for (int j = 1; j <= 8; ++j) {
                const Vec3d q = evaluate(s, breaks[i] + (breaks[i + 1] - breaks[i]) * j / 8.0, scratch);
                length += (q - prev).length();
                prev = q;
            }
        }
        Vec3d pa = evaluate(s, breaks[0], scratch);
        pts.push_back(pa);
        for (std::size_t i = 0; i + 1 < breaks.size(); ++i) {
            const Vec3d pb = evaluate(s, breaks[i + 1], scratch);
            flattenPiece(s, breaks[i], pa, breaks[i + 1], pb, 0.01 * length, 0, scratch, pts);
            pa = pb;
        }
    }
    for (const Vec3d& p : pts) {
        const Vec3f f(float(p.x()), float(p.y()), float(p.z()));
        if (!std::isfinite(f.x()) || !std::isfinite(f.y()) || !std::isfinite(f.z())) {
            return "the curve evaluates to a non-finite point (" + num(p.x()) + ", " + num(p.y()) + ", " + num(p.z()) + ")";
        }
        out.push_back(f);
    }
    if (curve.u0 > curve.u1) std::reverse(out.end() - std::ptrdiff_t(pts.size()), out.end());
    return {};
}

FreeFormCurve cubicCurve(CubicBasis basis, CurveWrap wrap, const Vec3f* points, std::size_t n)
{
    FreeFormCurve curve;
    curve.degree = 3;
    const bool phantoms = wrap == CurveWrap::Pinned && basis != CubicBasis::Bezier && n >= 2;
    if (phantoms) curve.points.push_back(2.0 * Vec3d(points[0]) - Vec3d(points[1]));
    for (std::size_t k = 0; k < n; ++k) curve.points.push_back(Vec3d(points[k]));
    if (phantoms) curve.points.push_back(2.0 * Vec3d(points[n - 1]) - Vec3d(points[n - 2]));
    if (wrap == CurveWrap::Periodic) {  // the first points again close the loop
        const std::size_t extra = std::min<std::size_t>(n, basis == CubicBasis::Bezier ? 1 : 3);
        for (std::size_t k = 0; k < extra; ++k) curve.points.push_back(Vec3d(points[k]));
    }
    const std::size_t m = curve.points.size();
    curve.weights.assign(m, 1.0);
    switch (basis) {
    case CubicBasis::Bezier:
        curve.basis = CurveBasis::Bezier;
        curve.u1 = double(m >= 4 ? (m - 1) / 3 : 1);  // segments (flattenCurve() refuses fewer than 4 points)
        break;
    case CubicBasis::BSpline:  // uniform and unclamped: the spans between knots 3 and m
        curve.basis = CurveBasis::BSpline;
        for (std::size_t k = 0; k < m + 4; ++k) curve.parms.push_back(double(k));
        curve.u0 = 3.0;
        curve.u1 = double(std::max<std::size_t>(m, 4));
        break;
    case CubicBasis::CatmullRom:
        curve.basis = CurveBasis::Cardinal;
        curve.u1 = double(std::max<std::size_t>(m, 4) - 3);
        break;
    }
    return curve;
}

std::size_t cubicVaryingCount(CubicBasis basis, CurveWrap wrap, std::size_t n)
{
    if (basis == CubicBasis::Bezier) {
        if (wrap == CurveWrap::Periodic) return n >= 3 ? n / 3 : 0;
        return n >= 4 ? (n - 1) / 3 + 1 : 0;
    }
    if (wrap == CurveWrap::Nonperiodic) return n >= 4 ? n - 2 : 0;
    return n >= 2 ? n : 0;  // pinned: n - 1 segments; periodic: n
}

CurvePosition positionAlong(std::size_t k, std::size_t count, std::size_t m)
{
    CurvePosition p;
    if (m <= 1 || count <= 1) return p;
    const double t = double(k) / double(count - 1) * double(m - 1);
    p.i0 = std::min<std::size_t>(std::size_t(t), m - 1);
    p.i1 = std::min<std::size_t>(p.i0 + 1, m - 1);
    p.f = float(t - double(p.i0));
    return p;
}

} // namespace vdbhair
