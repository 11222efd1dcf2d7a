/// @file FreeFormCurve.h
/// @brief The free-form curves of Wavefront OBJ (`cstype`, `deg`, `curv`, `parm u`; the OBJ 3.0
/// specification, "Free-form curve/surface attributes") evaluated to polylines: B-splines (NURBS
/// with `cstype rat bspline`) by de Boor's algorithm, Bezier curves as B-splines whose interior
/// knots have full multiplicity (so that they are evaluated exactly, segment by segment) and
/// cardinal splines (Catmull-Rom, tension 1/2) converted to their cubic Bezier segments.
///
/// **Sampling.** With a count, the curve is sampled at that many parameter values evenly spaced
/// over its range. Without one (0), each knot span is flattened by recursive bisection: a piece is
/// split until the curve's distance from the piece's chord, probed at 1/4, 1/2 and 3/4 of it, is
/// at most 5 % of the chord *and* at most 1 % of the curve's length, or after 10 halvings. The
/// first bound keeps the polyline's length within 1 % of the curve's (an arc of sagitta s over
/// chord c is longer than c by about 8/3 (s/c)^2 = 0.7 % at s/c = 0.05), and turns a curl into at
/// least 16 segments a turn; the second keeps a long, gently bent strand within 1 % of its length
/// of the curve everywhere. Measured (tests/io/TestFreeFormCurve.cc): a quarter circle (rational
/// quadratic Bezier) becomes 9 points, at most 0.34 % of its length from the arc and 0.16 % shorter;
/// a cubic B-spline of 60 control points curling 6 turns becomes 119 points, at most 0.04 % of its
/// length from the curve and 0.40 % shorter.
#pragma once

#include <vdbhair/Types.h>

#include <cstddef>
#include <string>
#include <vector>

namespace vdbhair {

/// `cstype`: the curve's basis. (Taylor and basis-matrix curves are refused by the reader.)
enum class CurveBasis { BSpline, Bezier, Cardinal };

/// A `curv` element as read.
struct FreeFormCurve
{
    CurveBasis basis = CurveBasis::BSpline;
    bool rational = false;
    int degree = 3;
    /// #N control points (world units) and their weights (1 for non-rational curves)
    std::vector<Vec3d> points;
    std::vector<double> weights;
    /// `parm u`: the knot vector (bspline, #N + degree + 1 values) or the parameter at each
    /// segment's ends (bezier, cardinal); empty: uniform over [u0, u1] (clamped for bspline)
    std::vector<double> parms;
    double u0 = 0.0, u1 = 1.0;  ///< the `curv` line's parameter range
};

/// The highest degree evaluated (de Boor costs degree^2 per point): OBJ exporters write 1 to 5.
constexpr int kMaxCurveDegree = 31;

/// @brief Evaluate @a curve into @a out (appended, root first: from u0 towards u1).
/// @param samples points to take evenly in parameter (at least 2), or 0 for the adaptive rule above
/// @return an empty string, or the rule the curve breaks (e.g. "degree 3 needs at least 4 control
/// points, got 2"), for the reader to put after the file and line.
std::string flattenCurve(const FreeFormCurve& curve, std::size_t samples, std::vector<Vec3f>& out);

/// The cubic bases of USD's `BasisCurves` and Alembic's `Curves` (RenderMan's curves: uniform
/// parametrization, a step of 3 control points per Bezier segment and 1 for the others).
enum class CubicBasis { Bezier, BSpline, CatmullRom };

/// How a cubic curve's ends are treated: `nonperiodic` (a B-spline and a Catmull-Rom curve start
/// near their second point and end near their last but one), `periodic` (closed: the first points
/// follow the last), `pinned` (USD: a B-spline and a Catmull-Rom curve reach their end points, by a
/// phantom point 2 P0 - P1 before the first and one after the last; a Bezier curve is unchanged).
enum class CurveWrap { Nonperiodic, Periodic, Pinned };

/// @brief The FreeFormCurve of a cubic curve of @a n control points, for flattenCurve() (which
/// states the rule when @a n does not make a curve, e.g. a Bezier curve of 5 points).
FreeFormCurve cubicCurve(CubicBasis basis, CurveWrap wrap, const Vec3f* points, std::size_t n);

/// @brief The values of "varying" interpolation on a cubic curve of @a n control points: one per
/// segment end (USD's UsdGeomBasisCurves and RenderMan's rule); 0 when @a n makes no segment.
std::size_t cubicVaryingCount(CubicBasis basis, CurveWrap wrap, std::size_t n);

/// Where point @a k of @a count points of a polyline evaluated from a curve lies among @a m values
/// given along the curve (per control point or per segment end, taken as evenly spaced): between
/// value i0 and i1, at fraction f.
struct CurvePosition
{
    std::size_t i0 = 0, i1 = 0;
    float f = 0.f;
};
CurvePosition positionAlong(std::size_t k, std::size_t count, std::size_t m);

} // namespace vdbhair
