// The fitter's piece parts (vdbhair/helicoid/impl/PrefitTrace.h, FitStarts.h, PieceFit.h) on
// analytic curves: circles and helicoid pieces of known parameters.
#include "../TestUtil.h"

#include <vdbhair/helicoid/HelicoidFit.h>
#include <vdbhair/helicoid/impl/FitStarts.h>
#include <vdbhair/helicoid/impl/FitTarget.h>
#include <vdbhair/helicoid/impl/PieceFit.h>
#include <vdbhair/helicoid/impl/PrefitTrace.h>

#include <cmath>

using namespace vdbhair;
using namespace vdbhair::fit;

namespace {

/// The circle of radius @a R in the x-y plane from the origin along +x, curving towards +y, at
/// arc length @a s: what k = (1/R, 0, 0, 0) traces from the identity frame (Helicoid.h).
Vec3d circleAt(double R, double s) { return Vec3d(R * std::sin(s / R), R * (1.0 - std::cos(s / R)), 0.0); }

/// @a n vertices on that circle, unevenly spaced (segments of 0.6 to 1.4 times @a spacing).
std::vector<Vec3f> circlePoints(double R, std::size_t n, double spacing)
{
    std::vector<Vec3f> pts;
    double s = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
        const Vec3d p = circleAt(R, s);
        pts.emplace_back(float(p.x()), float(p.y()), float(p.z()));
        s += spacing * (1.0 + 0.4 * std::sin(1.7 * double(i)));
    }
    return pts;
}

std::vector<Vec3f> tracedPoints(const std::vector<HelicoidPiece>& pieces, const FrameD& frame, std::size_t stride)
{
    HelicoidTrace t;
    tracePHelicoid(Vec3d(0.5, -1.0, 2.0), frame, pieces, 0.002, HelicoidIntegrator::RK4, t);
    std::vector<Vec3f> pts;
    for (std::size_t i = 0; i < t.points.size(); i += stride) pts.emplace_back(float(t.points[i].x()), float(t.points[i].y()), float(t.points[i].z()));
    return pts;
}

} // namespace

TEST_CASE("traceAtVertices: a circle's helicoid lands on the circle at each vertex's arc length", "[helicoid]")
{
    // Turning fast (one step per segment, subdivided) and slowly (steps over up to four segments,
    // Hermite-interpolated vertices): either way out[i] is the circle at the target's arc[i].
    for (const double R : {1.0, 50.0}) {
        const FitTarget target = makeFitTarget(circlePoints(R, 31, 0.2).data(), 31);
        Helicoid h;
        h.k = {1.0 / R, 0.0, 0.0, 0.0};
        std::vector<Vec3d> out;
        Vec3d endT;
        traceAtVertices(h, target, 0, 30, 0.05, out, &endT);
        REQUIRE(out.size() == 31);
        for (std::size_t i = 0; i < out.size(); ++i) {
            CAPTURE(R, i);
            REQUIRE((out[i] - circleAt(R, target.arc[i])).length() < 1e-4);
        }
        const double sEnd = target.arc[30];
        REQUIRE((endT - Vec3d(std::cos(sEnd / R), std::sin(sEnd / R), 0.0)).length() < 1e-4);
        // A fragment from a later vertex starts at h.p0 (its own root) and covers that fragment's arc.
        traceAtVertices(h, target, 10, 20, 0.05, out);
        REQUIRE(out.size() == 11);
        REQUIRE((out.back() - circleAt(R, target.arc[20] - target.arc[10])).length() < 1e-4);
    }
    // k = 0: a straight line, exactly at the arc lengths.
    const FitTarget target = makeFitTarget(circlePoints(3.0, 12, 0.3).data(), 12);
    Helicoid straight;
    std::vector<Vec3d> out;
    traceAtVertices(straight, target, 0, 11, 0.05, out);
    for (std::size_t i = 0; i < out.size(); ++i) REQUIRE((out[i] - Vec3d(target.arc[i], 0.0, 0.0)).length() < 1e-12);
}

TEST_CASE("pieceStarts: the circle's curvature, the hint rescaled, k = 0 and the previous piece", "[helicoid]")
{
    const double R = 2.0;
    const FitTarget target = makeFitTarget(circlePoints(R, 31, 0.1).data(), 31);
    PieceStart start;
    start.p0 = target.pts[0];
    start.q = FrameD{}.rolled(0.5);  // the strand's normal is +y: the roll start turns it back
    const std::size_t b = 30;
    const double L = target.arc[b];
    StartOptions all;
    std::vector<std::vector<double>> s = pieceStarts(target, start, b, 5, all);
    REQUIRE(s.size() == 2);  // the estimate and k = 0 (no hint, no previous piece)
    REQUIRE(s[0][0] == Approx(L / R).epsilon(0.02));  // kT L
    REQUIRE(s[0][3] == Approx(0.0).margin(1e-3));      // a plane curve: no torsion
    REQUIRE(s[0][4] == Approx(-0.5).margin(0.02));     // the roll
    REQUIRE(s[1] == std::vector<double>{0.0, 0.0, 0.0, 0.0});

    const std::vector<double> hint{1.0, 2.0, 3.0, 0.1, 0.2};
    start.previous = {0.4, 0.0, -0.1, 0.3};
    StartOptions nearest{PieceStarts::NearestFit, &hint, 2.0 * L};
    s = pieceStarts(target, start, b, 5, nearest);
    REQUIRE(s.size() == 1);
    REQUIRE(s[0] == std::vector<double>{0.5, 1.0, 1.5, 0.1, 0.2});  // curvatures scaled by L / hintLength
    all.hint = &hint;
    all.hintLength = 2.0 * L;
    s = pieceStarts(target, start, b, 4, all);
    REQUIRE(s.size() == 4);
    REQUIRE(s[0].size() == 4);  // no roll for 4 unknowns
    REQUIRE(s[1] == std::vector<double>{0.5, 1.0, 1.5, 0.1, 0.2});
    REQUIRE(s[3][0] == Approx(0.4 * L));
    REQUIRE(s[3][2] == Approx(-0.1 * L));
    REQUIRE(s[3][3] == 0.3);
}

TEST_CASE("PieceFitter: a piece of known parameters is fitted back, with and without the pre-fit", "[helicoid]")
{
    const FrameD frame = FrameD::fromTangentNormal(Vec3d(0.1, -1.0, 0.3), Vec3d(1, 0, 0));
    const std::vector<Vec3f> pts = tracedPoints({HelicoidPiece{{0.7, 0.1, 0.25, 0.15}, 4.0, 0.0}}, frame, 67);  // 30 vertices
    const FitTarget target = makeFitTarget(pts.data(), pts.size());
    const std::size_t last = target.pts.size() - 1;
    const double tolerance = 0.01 * target.length;
    for (const int prefit : {10, 0}) {
        FitParams params;
        params.prefitIterations = prefit;
        PieceFitter fitter(target, params, 0.25 * target.length / double(last));
        PieceStart start;
        start.p0 = target.pts[0];
        // The strand's own Frenet frame at the root, as fitStrand starts: the roll finds the rest.
        start.q = FrameD::fromTangentNormal(target.rootTangent, target.normal[0]);
        PieceFitOptions options;
        options.prefitStop = 0.7 * tolerance;
        std::vector<double> x = fitter.fitPiece(start, last, options);
        if (prefit) fitter.polish(x, start, last);
        CAPTURE(prefit, fitter.evaluations(), x[0], x[1], x[2], x[3], x[4]);
        REQUIRE(x.size() == 5);
        REQUIRE(fitter.evaluations() > 0);
        REQUIRE(fitter.acceptable(start, last, x, tolerance));
        // The grown piece ends at the strand's end, and Eq. 5 prefers it to a straight line.
        std::vector<Vec3d> grown;
        fitter.tracePoints(x, target.length, start.p0, start.q, fitter.step(), grown);
        REQUIRE((grown.back() - target.pts[last]).length() < tolerance);
        REQUIRE(fitter.objective(x, start, last) < fitter.objective({0.0, 0.0, 0.0, 0.0, 0.0}, start, last));
    }
}
