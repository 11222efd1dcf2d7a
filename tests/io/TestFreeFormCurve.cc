#include "../TestUtil.h"

#include <vdbhair/io/FreeFormCurve.h>

#include <algorithm>
#include <cmath>
#include <random>

using namespace vdbhair;
using Catch::Matchers::Contains;

namespace {

/// B-spline basis N_{i,p}(u) by the Cox-de Boor recursion (an oracle independent of de Boor's
/// algorithm, which the reader uses); right-continuous, with the last span closed at its end.
double basis(const std::vector<double>& t, std::size_t i, int p, double u, double uEnd)
{
    if (p == 0) {
        if (u == uEnd) return t[i] < t[i + 1] && t[i + 1] == uEnd ? 1.0 : 0.0;
        return t[i] <= u && u < t[i + 1] ? 1.0 : 0.0;
    }
    double v = 0.0;
    if (t[i + std::size_t(p)] > t[i]) v += (u - t[i]) / (t[i + std::size_t(p)] - t[i]) * basis(t, i, p - 1, u, uEnd);
    if (t[i + std::size_t(p) + 1] > t[i + 1]) {
        v += (t[i + std::size_t(p) + 1] - u) / (t[i + std::size_t(p) + 1] - t[i + 1]) * basis(t, i + 1, p - 1, u, uEnd);
    }
    return v;
}

/// The (rational) B-spline at u by the basis functions: sum N_i w_i P_i / sum N_i w_i.
Vec3d bsplinePoint(const std::vector<Vec3d>& P, const std::vector<double>& w, const std::vector<double>& t, int p, double u)
{
    const double uEnd = t[P.size()];
    Vec3d num(0.0);
    double den = 0.0;
    for (std::size_t i = 0; i < P.size(); ++i) {
        const double b = basis(t, i, p, u, uEnd) * w[i];
        num += b * P[i];
        den += b;
    }
    return num / den;
}

/// The cubic Bezier at t by Bernstein polynomials.
Vec3d bezier3(const Vec3d& a, const Vec3d& b, const Vec3d& c, const Vec3d& d, double t)
{
    const double s = 1.0 - t;
    return s * s * s * a + 3.0 * s * s * t * b + 3.0 * s * t * t * c + t * t * t * d;
}

double distanceToPolyline(const Vec3d& q, const std::vector<Vec3f>& line)
{
    double best = 1e300;
    for (std::size_t i = 0; i + 1 < line.size(); ++i) {
        const Vec3d a(line[i].x(), line[i].y(), line[i].z()), b(line[i + 1].x(), line[i + 1].y(), line[i + 1].z());
        const Vec3d ab = b - a;
        const double t = ab.lengthSqr() > 0 ? std::clamp((q - a).dot(ab) / ab.lengthSqr(), 0.0, 1.0) : 0.0;
        best = std::min(best, (q - (a + t * ab)).length());
    }
    return best;
}

double polylineLength(const std::vector<Vec3f>& line)
{
    double len = 0.0;
    for (std::size_t i = 0; i + 1 < line.size(); ++i) len += double((line[i + 1] - line[i]).length());
    return len;
}

FreeFormCurve makeCurve(CurveBasis basis, int degree, std::vector<Vec3d> points, std::vector<double> parms = {}, double u0 = 0.0, double u1 = 1.0)
{
    FreeFormCurve c;
    c.basis = basis;
    c.degree = degree;
    c.weights.assign(points.size(), 1.0);
    c.points = std::move(points);
    c.parms = std::move(parms);
    c.u0 = u0;
    c.u1 = u1;
    return c;
}

} // namespace

TEST_CASE("flattenCurve: Bezier segments equal their Bernstein form exactly", "[io][curves]")
{
    const std::vector<Vec3d> P{{0, 0, 0}, {1, 2, 0}, {3, 2, 1}, {4, 0, 1}, {5, -2, 1}, {7, -1, 0}, {8, 0, 0}};
    // Two cubic segments joined at u = 1 (parm u 0 1 2), sampled at 21 evenly spaced u.
    const FreeFormCurve c = makeCurve(CurveBasis::Bezier, 3, P, {0.0, 1.0, 2.0}, 0.0, 2.0);
    std::vector<Vec3f> out;
    REQUIRE(flattenCurve(c, 21, out).empty());
    REQUIRE(out.size() == 21);
    for (std::size_t i = 0; i < out.size(); ++i) {
        const double u = 2.0 * double(i) / 20.0;
        const Vec3d e = u <= 1.0 ? bezier3(P[0], P[1], P[2], P[3], u) : bezier3(P[3], P[4], P[5], P[6], u - 1.0);
        CAPTURE(i, u);
        REQUIRE(double((out[i] - Vec3f(float(e.x()), float(e.y()), float(e.z()))).length()) < 1e-5);
    }
}

TEST_CASE("flattenCurve: B-splines equal the Cox-de Boor basis sum, clamped, unclamped and rational", "[io][curves]")
{
    std::mt19937 rng(50);
    std::uniform_real_distribution<double> coord(-3.0, 3.0), weight(0.2, 3.0);
    for (int trial = 0; trial < 40; ++trial) {
        const int p = 1 + trial % 5;
        const std::size_t n = std::size_t(p) + 1 + std::size_t(trial % 7);
        std::vector<Vec3d> P(n);
        for (Vec3d& q : P) q = Vec3d(coord(rng), coord(rng), coord(rng));
        std::vector<double> t(n + std::size_t(p) + 1);
        const bool clamped = trial % 2 == 0;
        for (std::size_t i = 0; i < t.size(); ++i) {
            t[i] = clamped ? std::clamp(double(i) - p, 0.0, double(n - std::size_t(p))) : double(i) / double(t.size() - 1);
        }
        if (trial % 3 == 0 && n > std::size_t(p) + 2) t[std::size_t(p) + 1] = t[std::size_t(p) + 2];  // a repeated interior knot
        FreeFormCurve c = makeCurve(CurveBasis::BSpline, p, P, t, 0.0, clamped ? double(n - std::size_t(p)) : 1.0);  // Blender's "curv 0 1"
        if (trial % 4 == 1) {
            c.rational = true;
            for (double& w : c.weights) w = weight(rng);
        }
        std::vector<Vec3f> out;
        const std::size_t samples = 17;
        CAPTURE(trial, p, n, clamped, c.rational);
        REQUIRE(flattenCurve(c, samples, out).empty());
        REQUIRE(out.size() == samples);
        const double a = t[std::size_t(p)], b = t[n];  // the domain; the range 0..1 is clipped to it
        for (std::size_t i = 0; i < samples; ++i) {
            const double u = a + (b - a) * double(i) / double(samples - 1);
            const Vec3d e = bsplinePoint(P, c.weights, t, p, u);
            CAPTURE(i, u);
            REQUIRE(double((out[i] - Vec3f(float(e.x()), float(e.y()), float(e.z()))).length()) < 1e-4);
        }
        if (clamped) {  // a clamped curve starts and ends at its end control points
            REQUIRE(double((out.front() - Vec3f(float(P.front().x()), float(P.front().y()), float(P.front().z()))).length()) < 1e-5);
            REQUIRE(double((out.back() - Vec3f(float(P.back().x()), float(P.back().y()), float(P.back().z()))).length()) < 1e-5);
        }
    }
}

TEST_CASE("flattenCurve: a rational quadratic quarter circle, automatic samples within 1 % of its length", "[io][curves]")
{
    FreeFormCurve c = makeCurve(CurveBasis::Bezier, 2, {{1, 0, 0}, {1, 1, 0}, {0, 1, 0}});
    c.rational = true;
    c.weights = {1.0, std::sqrt(0.5), 1.0};
    std::vector<Vec3f> out;
    REQUIRE(flattenCurve(c, 0, out).empty());
    const double arc = M_PI / 2.0;
    double worst = 0.0;
    for (std::size_t i = 0; i < out.size(); ++i) REQUIRE(std::abs(double(out[i].length()) - 1.0) < 1e-6);  // every point on the circle
    for (int k = 0; k <= 1000; ++k) {  // the arc's distance from the polyline
        const double a = arc * k / 1000.0;
        worst = std::max(worst, distanceToPolyline(Vec3d(std::cos(a), std::sin(a), 0.0), out));
    }
    const double lengthError = 1.0 - polylineLength(out) / arc;
    WARN("quarter circle: " << out.size() << " points, max deviation " << worst / arc * 100.0 << " % of the length, length "
                            << lengthError * 100.0 << " % short");
    REQUIRE(worst <= 0.01 * arc);
    REQUIRE(lengthError >= 0.0);
    REQUIRE(lengthError <= 0.01);
    // An explicit count: 5 points, evenly in u (not in angle), all on the circle.
    out.clear();
    REQUIRE(flattenCurve(c, 5, out).empty());
    REQUIRE(out.size() == 5);
    REQUIRE(out.front().x() == Approx(1.f));
    REQUIRE(out.back().y() == Approx(1.f));
    REQUIRE(out[2].x() == Approx(std::sqrt(0.5f)).margin(1e-6));  // u = 1/2 is the arc's middle (symmetric weights)
}

TEST_CASE("flattenCurve: automatic samples keep a curly B-spline within 1 % of its length", "[io][curves]")
{
    // A cubic B-spline whose control points follow a helix of 6 turns (a curl), and an almost straight one.
    for (double turns : {6.0, 0.05}) {
        std::vector<Vec3d> P;
        const int n = 60;
        for (int i = 0; i < n; ++i) {
            const double a = 2.0 * M_PI * turns * i / (n - 1);
            P.emplace_back(0.5 * std::cos(a), 0.5 * std::sin(a), 0.08 * a);
        }
        const FreeFormCurve c = makeCurve(CurveBasis::BSpline, 3, P);
        std::vector<Vec3f> out, dense;
        REQUIRE(flattenCurve(c, 0, out).empty());
        REQUIRE(flattenCurve(c, 20000, dense).empty());  // the reference
        const double length = polylineLength(dense);
        double worst = 0.0;
        for (const Vec3f& q : dense) worst = std::max(worst, distanceToPolyline(Vec3d(q.x(), q.y(), q.z()), out));
        const double lengthError = 1.0 - polylineLength(out) / length;
        CAPTURE(turns, out.size(), worst / length, lengthError);
        WARN("helix B-spline of " << turns << " turns: " << out.size() << " points, max deviation " << worst / length * 100.0
                                  << " % of the length, length " << lengthError * 100.0 << " % short");
        REQUIRE(worst <= 0.01 * length);
        REQUIRE(std::abs(lengthError) <= 0.01);
    }
}

TEST_CASE("flattenCurve: Catmull-Rom (cardinal) passes through the inner control points", "[io][curves]")
{
    const std::vector<Vec3d> P{{0, 0, 0}, {1, 1, 0}, {2, 0, 1}, {3, 1, 1}, {4, 0, 0}};
    const FreeFormCurve c = makeCurve(CurveBasis::Cardinal, 3, P);  // 2 segments: P1-P2, P2-P3
    std::vector<Vec3f> out;
    REQUIRE(flattenCurve(c, 5, out).empty());
    REQUIRE(out.size() == 5);
    auto f = [](const Vec3d& v) { return Vec3f(float(v.x()), float(v.y()), float(v.z())); };
    REQUIRE((out[0] - f(P[1])).length() < 1e-6f);
    REQUIRE((out[2] - f(P[2])).length() < 1e-6f);
    REQUIRE((out[4] - f(P[3])).length() < 1e-6f);
    // Catmull-Rom at the middle of a segment: (-P0 + 9 P1 + 9 P2 - P3) / 16.
    REQUIRE((out[1] - f((-1.0 * P[0] + 9.0 * P[1] + 9.0 * P[2] - P[3]) / 16.0)).length() < 1e-6f);
    REQUIRE((out[3] - f((-1.0 * P[1] + 9.0 * P[2] + 9.0 * P[3] - P[4]) / 16.0)).length() < 1e-6f);
}

TEST_CASE("flattenCurve: reversed range, and each broken rule has its own message", "[io][curves]")
{
    const std::vector<Vec3d> P{{0, 0, 0}, {1, 1, 0}, {2, 1, 0}, {3, 0, 0}};
    std::vector<Vec3f> fwd, rev;
    REQUIRE(flattenCurve(makeCurve(CurveBasis::Bezier, 3, P, {}, 0.0, 1.0), 9, fwd).empty());
    REQUIRE(flattenCurve(makeCurve(CurveBasis::Bezier, 3, P, {}, 1.0, 0.0), 9, rev).empty());
    REQUIRE(std::equal(fwd.begin(), fwd.end(), rev.rbegin()));

    auto rule = [](const FreeFormCurve& c, std::size_t samples = 0) {
        std::vector<Vec3f> out;
        return flattenCurve(c, samples, out);
    };
    REQUIRE_THAT(rule(makeCurve(CurveBasis::BSpline, 3, {{0, 0, 0}, {1, 0, 0}})), Contains("degree 3 needs at least 4 control points, got 2"));
    REQUIRE_THAT(rule(makeCurve(CurveBasis::BSpline, 40, P)), Contains("degree 40 is outside 1..31"));
    REQUIRE_THAT(rule(makeCurve(CurveBasis::BSpline, 3, P, {0, 0, 0, 0, 1, 1, 1})), Contains("the knot vector (parm u) has 7 values; 4 control points of degree 3 need 8"));
    REQUIRE_THAT(rule(makeCurve(CurveBasis::BSpline, 3, P, {0, 0, 0, 1, 0.5, 1, 1, 1})), Contains("knot 5 (0.5) is below knot 4 (1); knots must not decrease"));
    REQUIRE_THAT(rule(makeCurve(CurveBasis::BSpline, 3, P, {0, 0, 0, 0, 1, 1, 1, 1}, 2.0, 3.0)), Contains("lies outside the knot vector's domain [0, 1]"));
    REQUIRE_THAT(rule(makeCurve(CurveBasis::BSpline, 3, P, {0, 0, 0, 0, 0, 0, 0, 0})), Contains("domain [0, 0] is empty"));
    REQUIRE_THAT(rule(makeCurve(CurveBasis::Bezier, 3, {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {3, 0, 0}, {4, 0, 0}})), Contains("needs 3 k + 1 control points (k segments), got 5"));
    REQUIRE_THAT(rule(makeCurve(CurveBasis::Bezier, 3, P, {0, 0})), Contains("is not above the one before"));
    REQUIRE_THAT(rule(makeCurve(CurveBasis::Cardinal, 2, P)), Contains("a cardinal curve has degree 3, not 2"));
    REQUIRE_THAT(rule(makeCurve(CurveBasis::Bezier, 3, P, {}, 1.0, 1.0)), Contains("must be finite and not empty"));
    REQUIRE_THAT(rule(makeCurve(CurveBasis::Bezier, 3, P), 1), Contains("a sample count of 1 makes no strand"));
    FreeFormCurve w = makeCurve(CurveBasis::Bezier, 3, P);
    w.rational = true;
    w.weights[2] = 0.0;
    REQUIRE_THAT(rule(w), Contains("control point 3 has weight 0; a rational curve needs weights above 0"));
    REQUIRE_THAT(rule(makeCurve(CurveBasis::Bezier, 3, {{0, 0, 0}, {1e39, 0, 0}, {1e39, 1e39, 0}, {3, 0, 0}}), 4), Contains("evaluates to a non-finite point"));
}
