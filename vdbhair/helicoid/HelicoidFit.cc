#include "HelicoidFit.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/Format.h>
#include <vdbhair/Progress.h>
#include <vdbhair/Quantile.h>
#include <vdbhair/helicoid/Frechet.h>
#include <vdbhair/helicoid/impl/FitTarget.h>
#include <vdbhair/helicoid/impl/PieceFit.h>
#include <vdbhair/helicoid/impl/PiecewiseFit.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <string>

namespace vdbhair {

namespace {

/// Each refit of a strand that used every piece allowed multiplies the tolerance by this (longer
/// pieces, so the budget reaches the tip): wavy at its stored 21 vertices 4.21 % -> 2.80 %.
constexpr double kRelaxFactor = 1.4;

/// Make every kT >= 0 by the half-turn symmetry: a piece traced from its frame rolled by π with
/// kT negated is the same curve, and ends in its end frame rolled by π. The roll therefore
/// carries over to every later piece, whose kT changes sign with it (@a carried).
void normalizeSign(HelicoidPiece& pc, bool first, FrameD& frame, bool& carried)
{
    if (carried) pc.k.kT = -pc.k.kT;  // the same curve from the frame rolled by π
    if (pc.k.kT >= 0.0) return;
    pc.k.kT = -pc.k.kT;
    if (first) frame = frame.rolled(M_PI);
    else pc.roll = std::remainder(pc.roll + M_PI, 2.0 * M_PI);
    carried = !carried;
}

StrandFit fitTarget(const fit::FitTarget& target, std::size_t n, const FitParams& params)
{
    const std::size_t last = target.pts.size() - 1;
    // Scene step: a quarter of the mean segment length unless given; Eq. 5 traces RK4 at four
    // times that (about one point per target vertex).
    double step = params.step;
    if (!(step > 0.0)) step = 0.25 * target.length / double(last);
    fit::PieceFitter fitter(target, params, step);

    StrandFit fit;
    fit.root = target.pts[0];
    fit.step = step;
    fit.length = target.length;
    fit.frame = FrameD::fromTangentNormal(target.rootTangent, target.normal[0]);

    // A fit with more floats than the points it replaces is pointless: 9 floats per strand and
    // 6 per piece against 3 per vertex.
    fit::PiecewiseOptions pieces;
    pieces.maxPieces = params.maxPieces;
    if (params.capByPoints) pieces.maxPieces = std::max(1, std::min(pieces.maxPieces, (3 * int(std::min<std::size_t>(n, 1 << 20)) - 10) / 6));
    pieces.minLength = std::max(fit::kMinFragment * target.length, 1e-12);
    const int maxPieces = pieces.maxPieces;

    // The whole fit, as grown, against the target densified to the same spacing.
    HelicoidTrace trace;
    std::vector<Vec3d> denseTarget;
    densifyPolyline(target.pts, 0, last, step, denseTarget);
    auto measure = [&](StrandFit& f) {
        traceFit(f, trace);
        f.frechet = discreteFrechet(denseTarget.data(), denseTarget.size(), trace.points.data(), trace.points.size());
    };
    const double tolerance = params.maxError * target.length;
    auto fitWithRetries = [&]() {
        StrandFit f = fit;  // root, frame, step, length
        pieces.tolerance = tolerance;
        fit::fitPieces(fitter, pieces, f);
        measure(f);
        // A strand that needs more pieces than it may have ends in a long last piece, however far
        // it strays: refit with a larger tolerance (longer pieces) and keep the closest fit.
        for (int retry = 1; retry <= params.relaxRetries && f.frechet > tolerance && int(f.pieces.size()) >= maxPieces; ++retry) {
            StrandFit relaxed = f;
            pieces.tolerance = tolerance * std::pow(kRelaxFactor, retry);
            fit::fitPieces(fitter, pieces, relaxed);
            measure(relaxed);
            if (relaxed.frechet < f.frechet) f = relaxed;
            if (int(relaxed.pieces.size()) < maxPieces) break;  // within the budget: larger tolerances only lose
        }
        f.stepDeviation = fitStepDeviation(f, 4, &f.clearance);
        return f;
    };
    StrandFit best = fitWithRetries();
    // Step convergence (issue 19): a fit whose trace moves at a quarter of its step is not a
    // streamline; refit it with every piece kept clear of its singular axis, and keep the
    // better-converged of the two.
    if (params.axisClearance > 0.0 && best.stepDeviation > params.stepDeviationLimit * tolerance) {
        pieces.kept = fit::KeptPieces::ClearOfAxis;
        StrandFit clear = fitWithRetries();
        pieces.kept = fit::KeptPieces::AsFitted;
        if (clear.stepDeviation < best.stepDeviation) best = clear;
    }
    fit = best;
    bool carried = false;
    for (std::size_t i = 0; i < fit.pieces.size(); ++i) normalizeSign(fit.pieces[i], i == 0, fit.frame, carried);
    traceFit(fit, trace);
    std::size_t pairs = 0;
    const double c = frechetCoupling(denseTarget.data(), denseTarget.size(), trace.points.data(), trace.points.size(), &pairs);
    fit.coupling = c / double(std::max<std::size_t>(1, pairs));
    fit.evaluations = fitter.evaluations();
    return fit;
}

} // namespace

void FitParams::validate(const char* where) const
{
    // A declared parameter by its declaration's names (fitParameters()); the others by their field's.
    const auto fail = [&](const std::string& field, const std::string& value, const std::string& rule) {
        const Param<FitParams>* declared = findParam(fitParameters(), field);
        const ParamName name = declared ? paramName(*declared) : ParamName{field, field};
        throw ParamError<ValueError>({std::string(where) + ": ", name, " " + value + ": " + rule});
    };
    if (!(maxError > 0.0) || !std::isfinite(maxError)) fail("max-error", formatNumber(maxError), "must be a positive fraction of the strand length");
    if (!(lambda >= 0.0) || !std::isfinite(lambda)) fail("lambda", formatNumber(lambda), "must be zero or positive");
    if (maxPieces < 1 || maxPieces > kMaxPieces) fail("max-pieces", std::to_string(maxPieces), "must be between 1 and " + std::to_string(kMaxPieces));
    if (relaxRetries < 0) fail("relaxRetries", std::to_string(relaxRetries), "must be 0 or more");
    if (maxEvaluations < kMinEvaluations) fail("max-evaluations", std::to_string(maxEvaluations), "must be at least " + std::to_string(kMinEvaluations));
    if (prefitIterations < 0) fail("prefit-iterations", std::to_string(prefitIterations), "must be 0 (none: Nelder-Mead alone, the paper's) or more");
    if (step != 0.0 && !(step > 0.0 && std::isfinite(step))) fail("step", formatNumber(step), "must be a positive finite length (0: a quarter of the mean segment length)");
    if (!(axisClearance >= 0.0) || !std::isfinite(axisClearance)) fail("axisClearance", formatNumber(axisClearance), "must be zero or positive (steps)");
    if (!(stepDeviationLimit > 0.0) || !std::isfinite(stepDeviationLimit)) fail("stepDeviationLimit", formatNumber(stepDeviationLimit), "must be a positive fraction of the tolerance");
}

const ParamTable<FitParams>& fitParameters()
{
    using P = FitParams;
    static const ParamTable<P> table = [] {
        ParamTable<P> t;
        auto maxError = makeParam<P>("max-error", "Accept a piece within this discrete Frechet distance, as a fraction of the strand length", "",
                                     member<P>([](P& p) -> double& { return p.maxError; }));
        maxError.min = 0.0;
        maxError.aboveMin = true;
        t.push_back(maxError);
        auto lambda = makeParam<P>("lambda", "Regularization weight of Eq. 5 (dimensionless: per turn of the piece)", "",
                                   member<P>([](P& p) -> double& { return p.lambda; }));
        lambda.min = 0.0;
        lambda.keyword = "lambda_";
        t.push_back(lambda);
        auto pieces = makeParam<P>("max-pieces", "Most pieces per strand (and at most (3 n - 10) / 6 for n vertices: a fit is never larger than its points)",
                                   "", member<P>([](P& p) -> int& { return p.maxPieces; }));
        pieces.min = 1;
        pieces.max = P::kMaxPieces;
        t.push_back(pieces);
        auto prefit = makeParam<P>("prefit-iterations", "Levenberg-Marquardt pre-fit iterations per piece and start", "",
                                   member<P>([](P& p) -> int& { return p.prefitIterations; }));
        prefit.min = 0;
        prefit.zeroMeans = "none, Nelder-Mead alone from the raw starts (the paper's method)";
        t.push_back(prefit);
        auto evaluations = makeParam<P>("max-evaluations", "Nelder-Mead evaluations per piece with no pre-fit (the pre-fit needs none)", "",
                                        member<P>([](P& p) -> int& { return p.maxEvaluations; }));
        evaluations.min = P::kMinEvaluations;
        t.push_back(evaluations);
        auto step = makeParam<P>("step", "Tracing step of the fits", "world units", member<P>([](P& p) -> double& { return p.step; }));
        step.min = 0.0;
        step.zeroMeans = "a quarter of each strand's mean segment length";
        t.push_back(step);
        auto roll = makeParam<P>("roll", "Also fit a roll angle of each piece's frame about its tangent (true or false)", "",
                                 member<P>([](P& p) -> bool& { return p.optimizeRoll; }));
        roll.valued = true;
        t.push_back(roll);
        t.push_back(makeParam<P>("skip-degenerate", "Leave out strands of zero length instead of failing", "",
                                 member<P>([](P& p) -> bool& { return p.skipDegenerate; })));
        return t;
    }();
    return table;
}

void traceFit(const StrandFit& fit, HelicoidTrace& out)
{
    tracePHelicoid(fit.root, fit.frame, fit.pieces, fit.step, HelicoidIntegrator::RK4, out);
}

double fitStepDeviation(const StrandFit& fit, int refinement, double* clearance)
{
    if (refinement < 1) throw ValueError("fitStepDeviation: refinement " + std::to_string(refinement) + " must be at least 1");
    HelicoidTrace coarse, fine;
    traceFit(fit, coarse);
    tracePHelicoid(fit.root, fit.frame, fit.pieces, fit.step / double(refinement), HelicoidIntegrator::RK4, fine);
    // Piece by piece: step j of the coarse trace is step refinement·j of the fine one (the
    // same arc length) until the last, shortened step; the pieces' ends are compared too.
    double worst = 0.0;
    const std::size_t r = std::size_t(refinement);
    for (std::size_t i = 0; i < fit.pieces.size(); ++i) {
        const std::size_t n = stepCount(fit.pieces[i].length, fit.step);
        const std::size_t nf = stepCount(fit.pieces[i].length, fit.step / double(refinement));
        const std::size_t c0 = coarse.joints[i], f0 = fine.joints[i];
        for (std::size_t j = 0; j <= n; ++j) {
            const std::size_t jf = j == n ? nf : std::min(nf, r * j);
            worst = std::max(worst, (coarse.points[c0 + j] - fine.points[f0 + jf]).length());
        }
    }
    if (clearance) *clearance = traceClearance(coarse, fit.step);
    return worst;
}

StrandFit fitStrand(const Vec3f* points, std::size_t n, const FitParams& params)
{
    params.validate("fitStrand");
    const fit::FitTarget target = fit::makeFitTarget(points, n);
    if (target.pts.size() < 2 || !(target.length > 0.0)) {
        throw ValueError("fitStrand: the strand has zero length (" + std::to_string(n) + " points, " +
                         std::to_string(target.pts.size()) + " distinct); there is no shape to fit");
    }
    return fitTarget(target, n, params);
}

std::vector<StrandFit> fitStrands(const StrandSet& strands, const FitParams& params, bool threaded,
                                  std::vector<std::string>* errors, openvdb::util::NullInterrupter* interrupter)
{
    params.validate("fitStrands");
    const std::size_t nS = strands.numStrands();
    std::vector<StrandFit> fits(nS);
    std::vector<std::string> messages(nS);
    ProgressCounter progress(interrupter, "fitting p-helicoids", nS, "strands");
    auto body = [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
            if (progress.stopped()) return;
            try {
                fits[i] = fitStrand(strands.data(i), strands.size(i), params);
            } catch (const Error& e) {
                messages[i] = "strand " + std::to_string(i) + ": " + e.what();
            }
            progress.add(1);
        }
    };
    if (threaded) tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nS, 4), body);
    else body(tbb::blocked_range<std::size_t>(0, nS));
    if (progress.stopped()) throw InterruptedError("fitStrands: interrupted");
    for (std::size_t i = 0; i < nS; ++i) {
        if (!messages[i].empty() && !errors) throw ValueError("fitStrands: " + messages[i]);
    }
    if (errors) *errors = std::move(messages);
    return fits;
}

FitSummary summarizeFits(const StrandSet& strands, const std::vector<StrandFit>& fits,
                         const std::vector<std::string>& errors, double maxError, double stepDeviationLimit)
{
    FitSummary s;
    s.strands = strands.numStrands();
    std::vector<double> relative;
    std::size_t pieces = 0, evaluations = 0;
    for (std::size_t i = 0; i < fits.size(); ++i) {
        if (i < errors.size() && !errors[i].empty()) {
            ++s.skipped;
            continue;
        }
        const StrandFit& f = fits[i];
        relative.push_back(f.frechet / f.length);
        pieces += f.pieces.size();
        evaluations += f.evaluations;
        const double dev = f.stepDeviation / f.length;
        s.stepDeviationMean += dev;
        s.stepDeviationMax = std::max(s.stepDeviationMax, dev);
        if (dev > stepDeviationLimit * maxError) ++s.unconverged;
    }
    s.fitted = relative.size();
    s.pointBytes = double(strands.numVertices()) * 12;
    if (relative.empty()) return s;
    for (double r : relative) s.meanRelative += r;
    s.meanRelative /= double(relative.size());
    s.stepDeviationMean /= double(relative.size());
    s.p95Relative = nearestRankQuantile(relative, 0.95);
    s.overMaxError = std::size_t(std::count_if(relative.begin(), relative.end(), [&](double r) { return r > maxError; }));
    s.piecesPerStrand = double(pieces) / double(s.fitted);
    s.fitBytes = double(s.fitted) * (3 + 6) * 4 + double(pieces) * 6 * 4;
    s.evaluationsPerStrand = double(evaluations) / double(s.fitted);
    return s;
}

SceneGuide guideFromFit(const StrandFit& fit)
{
    SceneGuide g;
    g.root = fit.root;
    g.frame = fit.frame;
    g.pieces = fit.pieces;
    g.step = fit.step;
    return g;
}

} // namespace vdbhair
