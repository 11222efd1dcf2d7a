// The split search (vdbhair/helicoid/impl/SplitSearch.h), both strategies, on a two-piece
// p-helicoid whose joint is known: a straight piece then a circle.
#include "../TestUtil.h"

#include <vdbhair/helicoid/HelicoidFit.h>
#include <vdbhair/helicoid/impl/FitTarget.h>
#include <vdbhair/helicoid/impl/PieceFit.h>
#include <vdbhair/helicoid/impl/SplitSearch.h>

using namespace vdbhair;
using namespace vdbhair::fit;

namespace {

/// 5 units straight, then 5 units of a circle of radius 1 (C¹ at the joint, §3.4), 61 vertices.
std::vector<Vec3f> straightThenCircle()
{
    HelicoidTrace t;
    const FrameD frame = FrameD::fromTangentNormal(Vec3d(0, 0, 1), Vec3d(1, 0, 0));
    tracePHelicoid(Vec3d(0.0), frame, {{{0.0, 0.0, 0.0, 0.0}, 5.0, 0.0}, {{1.0, 0.0, 0.0, 0.0}, 5.0, 0.0}}, 0.001, HelicoidIntegrator::RK4, t);
    std::vector<Vec3f> pts;
    const std::size_t stride = (t.points.size() - 1) / 60;
    for (std::size_t i = 0; i < t.points.size(); i += stride) pts.emplace_back(float(t.points[i].x()), float(t.points[i].y()), float(t.points[i].z()));
    const Vec3d& tip = t.points.back();
    if ((t.points.size() - 1) % stride) pts.emplace_back(float(tip.x()), float(tip.y()), float(tip.z()));
    return pts;
}

} // namespace

TEST_CASE("choosePiece: both split strategies cut a straight-then-circle strand near its joint", "[helicoid]")
{
    const std::vector<Vec3f> pts = straightThenCircle();
    const FitTarget target = makeFitTarget(pts.data(), pts.size());
    REQUIRE(target.length == Approx(10.0).epsilon(1e-3));
    const std::size_t last = target.pts.size() - 1;
    const SplitSearch strategy = GENERATE(SplitSearch::Forward, SplitSearch::TopDown);
    FitParams params;
    params.splitSearch = strategy;
    PieceFitter fitter(target, params, 0.25 * target.length / double(last));
    PieceStart start;
    start.p0 = target.pts[0];
    start.q = FrameD::fromTangentNormal(target.rootTangent, target.normal[0]);
    const double tolerance = params.maxError * target.length;
    FragmentCandidates candidates(fitter, start, tolerance);
    SplitOptions options;
    options.strategy = strategy;
    options.minLength = 0.03 * target.length;
    // No helicoid holds both: the whole remainder is not acceptable, and the split is found.
    std::vector<double> whole;
    REQUIRE_FALSE(fitRemainder(candidates, false, whole));
    const PieceChoice choice = choosePiece(candidates, options);
    CAPTURE(strategy == SplitSearch::Forward, choice.end, target.arc[choice.end], choice.upperTurn, fitter.evaluations());
    REQUIRE(choice.end < last);
    REQUIRE(target.arc[choice.end] >= 4.0);  // the joint is at 5: within 10 % of the strand
    REQUIRE(target.arc[choice.end] <= 6.0);
    REQUIRE(choice.x.size() == 5);

    // The whole strand: within maxError in a few pieces, the first ending near the joint.
    const StrandFit fit = fitStrand(pts.data(), pts.size(), params);
    CAPTURE(fit.frechet / fit.length, fit.pieces.size(), fit.pieces[0].length);
    REQUIRE(fit.frechet <= params.maxError * fit.length);
    REQUIRE(fit.pieces.size() >= 2);
    REQUIRE(fit.pieces.size() <= 4);
    REQUIRE(fit.pieces[0].length >= 4.0);
    REQUIRE(fit.pieces[0].length <= 6.0);
}

TEST_CASE("choosePiece: the last piece allowed takes the whole remainder whatever its error", "[helicoid]")
{
    const std::vector<Vec3f> pts = straightThenCircle();
    const FitTarget target = makeFitTarget(pts.data(), pts.size());
    const std::size_t last = target.pts.size() - 1;
    FitParams params;
    PieceFitter fitter(target, params, 0.25 * target.length / double(last));
    PieceStart start;
    start.p0 = target.pts[0];
    start.q = FrameD::fromTangentNormal(target.rootTangent, target.normal[0]);
    FragmentCandidates candidates(fitter, start, params.maxError * target.length);
    SplitOptions options;
    options.lastPiece = true;
    options.previousTurn = 0.7;
    const PieceChoice choice = choosePiece(candidates, options);
    REQUIRE(choice.end == last);
    REQUIRE(choice.upperTurn == 0.7);  // no split: the previous turning carries on
    REQUIRE_FALSE(fitter.acceptable(start, last, choice.x, params.maxError * target.length));
}
