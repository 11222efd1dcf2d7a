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

} // namespace vdbhair
