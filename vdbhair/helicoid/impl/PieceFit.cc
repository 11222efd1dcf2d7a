#include "PieceFit.h"

#include <vdbhair/helicoid/AnalyticHelicoidSampler.h>
#include <vdbhair/helicoid/Frechet.h>
#include <vdbhair/helicoid/impl/LevenbergMarquardt.h>
#include <vdbhair/helicoid/impl/NelderMead.h>
#include <vdbhair/helicoid/impl/PrefitTrace.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace vdbhair {
namespace fit {

Helicoid scaledHelicoid(const double* x, std::size_t dims, double L, const Vec3d& p0, const FrameD& q)
{
    Helicoid h;
    h.k = {x[0] / L, x[1] / L, x[2] / L, x[3]};
    h.q = dims > 4 ? q.rolled(x[4]) : q;
    h.p0 = p0;
    return h;
}

HelicoidPiece scaledPiece(const std::vector<double>& x, double L)
{
    HelicoidPiece pc;
    pc.k = {x[0] / L, x[1] / L, x[2] / L, x[3]};
    pc.length = L;
    pc.roll = x.size() > 4 ? x[4] : 0.0;
    return pc;
}

namespace {

/// Bounds of the scaled parameters: no RK4 step of Eq. 5's trace may turn more than a radian (a
/// quarter radian per step of the scene; neither integrator would follow more, and the fit would
/// exploit it); alpha within ±3; a roll within ±2 turns. This holds at the piece's root only
/// (there the singular axis is 1/|k| away); along the trace the axis penalty and acceptance keep
/// the distance.
void parameterBounds(double L, double evalStep, std::size_t dims, std::vector<double>& lower, std::vector<double>& upper)
{
    const double kmax = 1.0 * L / evalStep;
    lower = {-kmax, -kmax, -kmax, -3.0};
    upper = {kmax, kmax, kmax, 3.0};
    if (dims > 4) { lower.push_back(-4.0 * M_PI); upper.push_back(4.0 * M_PI); }
}

} // namespace

/// The pre-fit's smooth least-squares stand-in for Eq. 5 over [a, b]: residuals of the arc-length
/// correspondence (both curves parameterized by arc length), (trace(s_i) - h_i) / (L sqrt(n)) for
/// each vertex after the first, the end point again with weight 1 (Eq. 5 counts it twice), a small
/// Tikhonov term on k, the end direction against the strand's (kEndTangentWeight) and the axis
/// penalty (kPrefitAxisWeight). O(n) per evaluation.
class PieceFitter::PrefitProblem : public LeastSquaresProblem
{
public:
    PrefitProblem(PieceFitter& fitter, const PieceStart& start, std::size_t b, double stop)
        : mF(fitter), mS(start), mB(b), mL(fitter.mTarget.arc[b] - fitter.mTarget.arc[start.a]), mStop(stop)
    {
        parameterBounds(mL, fitter.mEvalStep, kMaxUnknowns, mLower, mUpper);
    }

    std::size_t residualCount() const override { return 3 * (mB - mS.a) + 3 + 4 + 3 + 1; }

    void residuals(const double* x, std::size_t dims, double* r) override
    {
        const FitTarget& target = mF.mTarget;
        const FitParams& params = mF.mParams;
        const std::size_t a = mS.a, b = mB;
        ++mF.mEvaluations;
        Vec3d endT;
        const Helicoid h = scaledHelicoid(x, dims, mL, mS.p0, mS.q);
        std::vector<Vec3d>& trace = mF.mPrefitTrace;
        traceAtVertices(h, target, a, b, mF.mEvalStep, trace, &endT);
        const std::size_t n = b - a;
        const double L = mL;
        const double w = 1.0 / (L * std::sqrt(double(n)));
        for (std::size_t i = 1; i <= n; ++i) {
            const Vec3d d = (trace[i] - target.pts[a + i]) * w;
            for (int c = 0; c < 3; ++c) r[3 * (i - 1) + std::size_t(c)] = d[c];
        }
        const Vec3d e = (trace[n] - target.pts[b]) / L;
        for (int c = 0; c < 3; ++c) r[3 * n + std::size_t(c)] = e[c];
        const double reg = std::sqrt(params.lambda) * 0.1;
        for (int c = 0; c < 4; ++c) r[3 * n + 3 + std::size_t(c)] = reg * x[c];
        // The end direction: the next piece starts with this piece's end frame (C¹), so a
        // piece leaving the strand at an angle hands its successor a detour.
        const std::size_t last = target.pts.size() - 1;
        const Vec3d dir = (target.pts[std::min(b + 1, last)] - target.pts[b - 1]).unitSafe();
        const Vec3d et = (endT - dir) * kEndTangentWeight;
        for (int c = 0; c < 3; ++c) r[3 * n + 7 + std::size_t(c)] = et[c];
        // Keep away from the singular axis (at the vertices; acceptance checks every step), so
        // that the pre-fit does not settle on a discretization artefact that acceptance refuses.
        double clearance = std::numeric_limits<double>::infinity();
        if (params.axisClearance > 0.0) {
            for (const Vec3d& p : trace) clearance = std::min(clearance, h.axisDistance(p));
        }
        r[3 * n + 10] = kPrefitAxisWeight * mF.axisPenalty(clearance / mF.mStep);
    }

    void clamp(std::vector<double>& x) const override
    {
        for (std::size_t i = 0; i < x.size(); ++i) x[i] = std::max(mLower[i], std::min(mUpper[i], x[i]));
    }

    /// Every vertex within the stop distance of its arc-length counterpart.
    bool closeEnough(const double* r) const override
    {
        if (!(mStop > 0.0)) return false;
        const std::size_t n = mB - mS.a;
        const double wv = 1.0 / (mL * std::sqrt(double(n)));
        const double lim = mStop * mStop * wv * wv;
        for (std::size_t i = 0; i < n; ++i) {
            const double d2 = r[3 * i] * r[3 * i] + r[3 * i + 1] * r[3 * i + 1] + r[3 * i + 2] * r[3 * i + 2];
            if (d2 > lim) return false;
        }
        return true;
    }

private:
    PieceFitter& mF;
    const PieceStart& mS;
    std::size_t mB;
    double mL, mStop;
    std::vector<double> mLower, mUpper;
};

const std::vector<Vec3d>& PieceFitter::DenseFragment::get(const FitTarget& target, std::size_t first, std::size_t last, double spacing)
{
    if (first != a || last != b) {
        densifyPolyline(target.pts, first, last, spacing, pts);
        a = first;
        b = last;
    }
    return pts;
}

PieceFitter::PieceFitter(const FitTarget& target, const FitParams& params, double step)
    : mTarget(target), mParams(params), mStep(step), mEvalStep(4.0 * step)
{
}

double PieceFitter::tracePoints(const std::vector<double>& x, double L, const Vec3d& p0, const FrameD& q, double h,
                                std::vector<Vec3d>& out) const
{
    const Helicoid hel = scaledHelicoid(x.data(), x.size(), L, p0, q);
    const std::size_t n = stepCount(L, h);
    out.resize(n + 1);
    Vec3d p = p0;
    // The streamline engine's RK4 through the analytic helicoid, theta unwrapped from the root.
    AnalyticHelicoidSampler sampler(hel);
    StreamlineIntegrator<AnalyticHelicoidSampler> rk4(sampler, Integrator::RK4);
    Vec3d k1 = sampler.tangent(p);
    out[0] = p;
    double clearance = hel.axisDistance(p);
    for (std::size_t j = 0; j < n; ++j) {
        const double hs = (j + 1 == n) ? L - double(n - 1) * h : h;
        Vec3d next;
        rk4.advanceFrom(p, k1, hs, next);
        p = next;
        k1 = sampler.tangent(p);
        out[j + 1] = p;
        clearance = std::min(clearance, hel.axisDistance(p));
    }
    return clearance / mStep;
}

void PieceFitter::tracePiece(const std::vector<double>& x, double L, const Vec3d& p0, const FrameD& q, double h, HelicoidTrace& out) const
{
    tracePHelicoid(p0, q, {scaledPiece(x, L)}, h, HelicoidIntegrator::RK4, out);
}

double PieceFitter::axisPenalty(double clearance) const
{
    const double c = mParams.axisClearance;
    return c > 0.0 && clearance < c ? c / std::max(clearance, 1e-3) - 1.0 : 0.0;
}

double PieceFitter::objective(const std::vector<double>& x, const PieceStart& start, std::size_t b)
{
    ++mEvaluations;
    const double L = mTarget.arc[b] - mTarget.arc[start.a];
    const double clearance = tracePoints(x, L, start.p0, start.q, mEvalStep, mPoints);
    const std::vector<Vec3d>& frag = mDense.get(mTarget, start.a, b, mEvalStep);
    std::size_t pairs = 0;
    const double c = frechetCoupling(frag.data(), frag.size(), mPoints.data(), mPoints.size(), &pairs);
    const double turns = std::sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]) / (2.0 * M_PI) + std::abs(x[3]);
    // The end point matters twice: the next piece starts there, and can only bend, not jump.
    const double end = (mPoints.back() - mTarget.pts[b]).length();
    return (c / double(std::max<std::size_t>(1, pairs)) + end) / L + mParams.lambda * turns + axisPenalty(clearance);
}

bool PieceFitter::acceptable(const PieceStart& start, std::size_t b, const std::vector<double>& x, double eps)
{
    const double L = mTarget.arc[b] - mTarget.arc[start.a];
    // A trace near the singular axis changes with the step: not a streamline.
    if (tracePoints(x, L, start.p0, start.q, mStep, mPoints) < mParams.axisClearance) return false;
    if (b + 1 < mTarget.pts.size() && (mPoints.back() - mTarget.pts[b]).length() > kAcceptEndOffset * eps) return false;
    const std::vector<Vec3d>& frag = mDenseExact.get(mTarget, start.a, b, mStep);
    return discreteFrechetWithin(frag.data(), frag.size(), mPoints.data(), mPoints.size(), eps);
}

void PieceFitter::minimize(std::vector<double>& x, const PieceStart& start, std::size_t b, double initialStep, double tolerance,
                           int evaluations)
{
    NelderMeadOptions o;
    parameterBounds(mTarget.arc[b] - mTarget.arc[start.a], mEvalStep, x.size(), o.lower, o.upper);
    o.initialStep.assign(x.size(), initialStep);
    if (x.size() > 4) o.initialStep[4] = 0.8 * initialStep;
    o.xtolAbs = tolerance;
    o.ftolRel = tolerance * 1e-3;
    o.maxEvaluations = evaluations;
    minimizeNelderMead([&](const std::vector<double>& v) { return objective(v, start, b); }, x, o);
}

void PieceFitter::polish(std::vector<double>& x, const PieceStart& start, std::size_t b)
{
    minimize(x, start, b, kPolishStep, kPolishTolerance, kPolishEvaluations);
}

double PieceFitter::prefitFrom(LeastSquaresProblem& problem, std::vector<double>& x) const
{
    LevenbergMarquardtOptions o;
    o.maxIterations = mParams.prefitIterations;
    o.minGain = kPrefitGain;
    return minimizeLevenbergMarquardt(problem, x, o);
}

std::vector<double> PieceFitter::fitPiece(const PieceStart& start, std::size_t b, const PieceFitOptions& options)
{
    const std::size_t dims = mParams.optimizeRoll ? 5 : 4;
    std::vector<std::vector<double>> starts = pieceStarts(mTarget, start, b, dims, options.starts);
    std::vector<double> best;
    double bestF = std::numeric_limits<double>::max();
    if (mParams.prefitIterations > 0) {
        // Pre-fit from the starts that the smooth objective ranks first.
        const std::size_t maxRuns = std::size_t(std::max(1, options.startsToRun > 0 ? options.startsToRun : kPrefitStarts));
        std::vector<std::pair<double, std::size_t>> ranked;
        const bool rank = starts.size() > maxRuns;
        PrefitProblem problem(*this, start, b, options.prefitStop);
        for (std::size_t i = 0; i < starts.size(); ++i) {
            starts[i].resize(dims, 0.0);
            ranked.emplace_back(rank ? residualCost(problem, starts[i]) : 0.0, i);
        }
        if (ranked.size() > 1) std::sort(ranked.begin(), ranked.end());
        const std::size_t runs = std::min(ranked.size(), maxRuns);
        for (std::size_t i = 0; i < runs; ++i) {
            std::vector<double> x = starts[ranked[i].second];
            const double f = prefitFrom(problem, x);
            if (f < bestF) { bestF = f; best = x; }
            // The first pre-fit that is good enough ends the search (in the starts' order).
            if (options.accept && i + 1 < runs && options.accept(x)) { best = x; break; }
        }
        return best;  // scaled by this fragment's L
    }
    // Without a pre-fit (the paper's method): Nelder–Mead on Eq. 5 from the most promising start.
    for (std::vector<double> x : starts) {
        x.resize(dims, 0.0);
        const double f = objective(x, start, b);
        if (f < bestF) { bestF = f; best = x; }
    }
    minimize(best, start, b, kSearchStep, kSearchTolerance, mParams.maxEvaluations);
    return best;  // scaled by this fragment's L
}

} // namespace fit
} // namespace vdbhair
