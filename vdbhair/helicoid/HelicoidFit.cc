#include "HelicoidFit.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/Progress.h>
#include <vdbhair/helicoid/Frechet.h>
#include <vdbhair/strands/Frames.h>
#include <vdbhair/strands/Measures.h>

#include <nlopt.hpp>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

namespace vdbhair {

namespace {

Vec3f toF(const Vec3d& v) { return Vec3f(float(v.x()), float(v.y()), float(v.z())); }

/// The target strand: distinct points, their arc lengths, and its curvature profile.
struct Target
{
    std::vector<Vec3d> pts;
    std::vector<double> arc;
    std::vector<float> curvature;
    double length = 0.0;
};

/// The polyline points[a..b] with points inserted so that no gap exceeds @a spacing. Discrete
/// Fréchet measures compare vertices: a sparse target against a dense trace would report half a
/// target segment even for a perfect fit, so targets are densified to the trace's spacing.
void densify(const std::vector<Vec3d>& pts, std::size_t a, std::size_t b, double spacing, std::vector<Vec3d>& out)
{
    out.clear();
    out.push_back(pts[a]);
    for (std::size_t i = a; i < b; ++i) {
        const Vec3d d = pts[i + 1] - pts[i];
        const int n = std::max(1, int(std::ceil(d.length() / spacing - 1e-9)));
        for (int k = 1; k <= n; ++k) out.push_back(pts[i] + d * (double(k) / n));
    }
}

/// Everything one fit needs while it runs (one per strand).
struct Fitter
{
    const Target& target;
    const FitParams& params;
    double step;      ///< the scene's step: pieces are chained (and regrown) with RK4 at this step
    double evalStep;  ///< the objective's step: RK4 follows the same streamline with 4x fewer points
    std::size_t evaluations = 0;

    Fitter(const Target& t, const FitParams& p, double s) : target(t), params(p), step(s), evalStep(4.0 * s) {}

    HelicoidTrace trace;  // scratch
    std::vector<Vec3d> dense;           // the current fragment, densified to evalStep
    std::size_t denseA = ~std::size_t(0), denseB = 0;

    const std::vector<Vec3d>& fragment(std::size_t a, std::size_t b)
    {
        if (a != denseA || b != denseB) {
            densify(target.pts, a, b, evalStep, dense);
            denseA = a;
            denseB = b;
        }
        return dense;
    }

    /// Trace one piece with scaled parameters x = (kT L, kN L, kB L, alpha[, roll]): RK4 at the
    /// objective's step, or (@a exact) Euler at the scene's step, as the strand will be grown.
    void tracePiece(const std::vector<double>& x, double L, const Vec3d& p0, const FrameD& q, HelicoidTrace& out,
                    bool exact = false) const
    {
        HelicoidPiece pc;
        pc.k = {x[0] / L, x[1] / L, x[2] / L, x[3]};
        pc.length = L;
        pc.roll = x.size() > 4 ? x[4] : 0.0;
        if (exact) tracePHelicoid(p0, q, {pc}, step, HelicoidIntegrator::RK4, out);
        else tracePHelicoid(p0, q, {pc}, evalStep, HelicoidIntegrator::RK4, out);
    }

    /// Eq. 5, scale-free: the coupling's mean leash over L, plus λ times the turns of the piece.
    double objective(const std::vector<double>& x, std::size_t a, std::size_t b, const Vec3d& p0, const FrameD& q)
    {
        ++evaluations;
        const double L = target.arc[b] - target.arc[a];
        tracePiece(x, L, p0, q, trace);
        const std::vector<Vec3d>& frag = fragment(a, b);
        std::size_t pairs = 0;
        const double c = frechetCoupling(frag.data(), frag.size(), trace.points.data(), trace.points.size(), &pairs);
        const double turns = std::sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]) / (2.0 * M_PI) + std::abs(x[3]);
        // The end point matters twice: the next piece starts there, and can only bend, not jump.
        const double end = (trace.points.back() - target.pts[b]).length();
        return (c / double(std::max<std::size_t>(1, pairs)) + end) / L + params.lambda * turns;
    }

    /// Nelder–Mead from @a start; returns the best x and its objective.
    double minimize(std::vector<double>& x, std::size_t a, std::size_t b, const Vec3d& p0, const FrameD& q)
    {
        nlopt::opt opt(nlopt::LN_NELDERMEAD, unsigned(x.size()));
        struct Data { Fitter* self; std::size_t a, b; const Vec3d* p0; const FrameD* q; } data{this, a, b, &p0, &q};
        opt.set_min_objective(
            [](const std::vector<double>& v, std::vector<double>&, void* d) {
                Data& dd = *static_cast<Data*>(d);
                const double f = dd.self->objective(v, dd.a, dd.b, *dd.p0, *dd.q);
                return std::isfinite(f) ? f : 1e30;
            },
            &data);
        // Bounds: no RK4 step may turn more than a radian (a quarter radian per Euler step of
        // the scene; neither integrator would follow more, and the fit would exploit it);
        // alpha within ±3.
        const double L = target.arc[b] - target.arc[a];
        const double kmax = 1.0 * L / evalStep;
        std::vector<double> lower{-kmax, -kmax, -kmax, -3.0}, upper{kmax, kmax, kmax, 3.0};
        if (x.size() > 4) { lower.push_back(-4.0 * M_PI); upper.push_back(4.0 * M_PI); }
        opt.set_lower_bounds(lower);
        opt.set_upper_bounds(upper);
        for (std::size_t i = 0; i < x.size(); ++i) x[i] = std::max(lower[i], std::min(upper[i], x[i]));
        std::vector<double> stepSizes(x.size(), 0.5);
        if (x.size() > 4) stepSizes[4] = 0.4;
        opt.set_initial_step(stepSizes);
        opt.set_xtol_abs(1e-4);
        opt.set_ftol_rel(1e-7);
        opt.set_maxeval(params.maxEvaluations);
        double f = 0.0;
        try {
            opt.optimize(x, f);
        } catch (const nlopt::roundoff_limited&) {
            // the best point so far is in x
        } catch (const std::exception&) {
            f = objective(x, a, b, p0, q);
        }
        return f;
    }

    /// Mean curvature and torsion over the first third of the fragment [a, b].
    void startEstimate(std::size_t a, std::size_t b, double& kappa, double& tau) const
    {
        const std::size_t n = b - a + 1;
        std::vector<Vec3f> pts(n);
        for (std::size_t i = 0; i < n; ++i) pts[i] = toF(target.pts[a + i]);
        std::vector<float> k(n), t(n);
        curvatureProfile(pts.data(), n, k.data());
        torsionProfile(pts.data(), n, t.data());
        const std::size_t m = std::max<std::size_t>(1, n / 3);
        kappa = tau = 0.0;
        for (std::size_t i = 0; i < m; ++i) { kappa += k[i]; tau += t[i]; }
        kappa /= double(m);
        tau /= double(m);
    }

    /// Fit one piece to the fragment [a, b] from (p0, q); q fixed (a roll may be fitted).
    std::vector<double> fitPiece(std::size_t a, std::size_t b, const Vec3d& p0, const FrameD& q, const std::vector<double>* previous,
                                 bool allowRoll, bool thorough)
    {
        const double L = target.arc[b] - target.arc[a];
        double kappa, tau;
        startEstimate(a, b, kappa, tau);
        const std::size_t dims = allowRoll ? 5 : 4;
        std::vector<std::vector<double>> starts;
        starts.push_back({kappa * L, 0.0, 0.0, kappa > 1e-9 ? std::max(-2.0, std::min(2.0, tau / kappa)) : 0.0});
        if (thorough) starts.push_back({0.0, 0.0, 0.0, 0.0});
        if (previous && thorough) starts.push_back({(*previous)[0] * L, (*previous)[1] * L, (*previous)[2] * L, (*previous)[3]});
        // Nelder–Mead from the most promising start only (one evaluation each to choose).
        std::vector<double> best;
        double bestF = std::numeric_limits<double>::max();
        for (std::vector<double> x : starts) {
            x.resize(dims, 0.0);
            const double f = objective(x, a, b, p0, q);
            if (f < bestF) { bestF = f; best = x; }
        }
        minimize(best, a, b, p0, q);
        return best;  // scaled by this fragment's L
    }
};

/// Distinct points of the strand (repeated points removed), their arc lengths and curvature.
Target makeTarget(const Vec3f* points, std::size_t n)
{
    Target t;
    for (std::size_t i = 0; i < n; ++i) {
        const Vec3d p(points[i]);
        if (!t.pts.empty() && p == t.pts.back()) continue;
        t.pts.push_back(p);
    }
    t.arc.resize(t.pts.size());
    if (!t.pts.empty()) t.arc[0] = 0.0;
    for (std::size_t i = 1; i < t.pts.size(); ++i) t.arc[i] = t.arc[i - 1] + (t.pts[i] - t.pts[i - 1]).length();
    t.length = t.arc.empty() ? 0.0 : t.arc.back();
    std::vector<Vec3f> f(t.pts.size());
    for (std::size_t i = 0; i < f.size(); ++i) f[i] = toF(t.pts[i]);
    t.curvature.resize(f.size());
    curvatureProfile(f.data(), f.size(), t.curvature.data());
    return t;
}

std::size_t indexAtArc(const Target& t, double s)
{
    return std::size_t(std::lower_bound(t.arc.begin(), t.arc.end(), s) - t.arc.begin());
}

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

} // namespace

void traceFit(const StrandFit& fit, HelicoidTrace& out)
{
    tracePHelicoid(fit.root, fit.frame, fit.pieces, fit.step, HelicoidIntegrator::RK4, out);
}

StrandFit fitStrand(const Vec3f* points, std::size_t n, const FitParams& params)
{
    const Target target = makeTarget(points, n);
    if (target.pts.size() < 2 || !(target.length > 0.0)) {
        throw ValueError("fitStrand: the strand has zero length (" + std::to_string(n) + " points, " +
                         std::to_string(target.pts.size()) + " distinct); there is no shape to fit");
    }
    const std::size_t last = target.pts.size() - 1;
    // Scene step: a quarter of the mean segment length unless given; the objective traces RK4
    // at four times that (about one point per target vertex).
    double step = params.step;
    if (!(step > 0.0)) step = 0.25 * target.length / double(last);
    Fitter fitter(target, params, step);

    StrandFit fit;
    fit.root = target.pts[0];
    fit.step = step;
    fit.length = target.length;
    {
        std::vector<Vec3f> f(target.pts.size());
        for (std::size_t i = 0; i < f.size(); ++i) f[i] = toF(target.pts[i]);
        std::vector<Frame> frames(f.size());
        frenetFrames(f.data(), f.size(), frames.data());
        fit.frame = FrameD::fromTangentNormal(Vec3d(frames[0].t), Vec3d(frames[0].n));
    }

    const double tolerance = params.maxError * target.length;
    const double minLength = std::max(params.minFragment * target.length, 1e-12);
    std::size_t a = 0;
    Vec3d p0 = fit.root;
    FrameD q = fit.frame;
    std::vector<double> previous;
    HelicoidTrace trace;
    std::vector<Vec3d> denseTarget;
    while (a < last) {
        const bool allowRoll = params.optimizeRoll;
        const double remaining = target.length - target.arc[a];
        auto fitTo = [&](std::size_t b, std::vector<double>& x, bool thorough) {
            x = fitter.fitPiece(a, b, p0, q, previous.empty() ? nullptr : &previous, allowRoll, thorough);
            const double L = target.arc[b] - target.arc[a];
            fitter.tracePiece(x, L, p0, q, trace, /*exact=*/true);
            densify(target.pts, a, b, step, denseTarget);
            return discreteFrechet(denseTarget.data(), denseTarget.size(), trace.points.data(), trace.points.size());
        };
        std::vector<double> x;
        const double err = fitTo(last, x, true);
        std::size_t b = last;
        const bool lastPiece = int(fit.pieces.size()) + 1 >= params.maxPieces || remaining < 2.0 * minLength || last - a < 3;
        if (!(err <= tolerance) && !lastPiece) {
            // Upper limit: the longest prefix whose fit is acceptable (the paper's Fréchet
            // threshold), by bisection over the vertices between the minimum fragment and the
            // splitFraction of the remainder (then the remainder itself, which failed above).
            const std::size_t lo = std::min(last - 1, std::max(a + 2, indexAtArc(target, target.arc[a] + minLength)));
            std::size_t hi = std::min(last - 1, std::max(lo, indexAtArc(target, target.arc[a] + params.splitFraction * remaining)));
            std::vector<double> xu, xt;
            std::size_t u = lo;
            double eu = fitTo(lo, xu, true);
            if (eu <= tolerance) {
                // Is the splitFraction itself acceptable? Then search above it, else below.
                const double eh = hi > lo ? fitTo(hi, xt, true) : eu;
                std::size_t good = lo, bad = last;
                if (hi > lo) {
                    if (eh <= tolerance) { good = hi; xu = xt; eu = eh; }
                    else bad = hi;
                }
                while (bad - good > 1) {
                    const std::size_t mid = (good + bad) / 2;
                    const double em = fitTo(mid, xt, true);
                    if (em <= tolerance) { good = mid; xu = xt; eu = em; }
                    else bad = mid;
                }
                u = good;
            }
            // Backtrack from u along the curvature profile to where fragment and fit agree best:
            // in curvature (the paper's criterion) and, since the next piece starts there, in
            // position and direction.
            const double Lu = target.arc[u] - target.arc[a];
            fitter.tracePiece(xu, Lu, p0, q, trace);
            std::vector<Vec3f> tf(trace.points.size());
            for (std::size_t i = 0; i < tf.size(); ++i) tf[i] = toF(trace.points[i]);
            std::vector<float> fitCurv(tf.size());
            curvatureProfile(tf.data(), tf.size(), fitCurv.data());
            std::size_t split = u;
            double bestScore = std::numeric_limits<double>::max();
            // A fit that ends on the strand, in its direction, keeps its whole length: backtracking
            // exists for the fits that drift near their end.
            const double endOffset = (trace.points.back() - target.pts[u]).length();
            const double endAngle = std::acos(std::max(-1.0, std::min(1.0, trace.frames.back().t.dot((target.pts[u] - target.pts[u - 1]).unitSafe()))));
            const bool keepU = endOffset < 0.5 * tolerance && endAngle < 0.1;
            // The window: the last 40 % of the piece (backtracking adjusts the split; it must not
            // throw away the length the bisection found acceptable).
            const double windowStart = std::max(target.arc[a] + minLength, target.arc[u] - 0.4 * (target.arc[u] - target.arc[a]));
            for (std::size_t v = u; !keepU && v > a + 1 && target.arc[v] >= windowStart; --v) {
                const double s = target.arc[v] - target.arc[a];
                const std::size_t m = std::min(tf.size() - 1, std::size_t(std::lround(s / fitter.evalStep)));
                const Vec3d targetDir = (target.pts[std::min(v + 1, last)] - target.pts[v - 1]).unitSafe();
                const double angle = std::acos(std::max(-1.0, std::min(1.0, trace.frames[m].t.dot(targetDir))));
                const double score = std::abs(double(target.curvature[v]) - double(fitCurv[m])) * target.length + angle / 0.05;
                if (score < bestScore) { bestScore = score; split = v; }
            }
            b = split;
            x = xu;
            // The piece fitted to [a, u], kept up to the split (the scaled x refer to Lu).
            const double Lb = target.arc[b] - target.arc[a];
            for (int k = 0; k < 3; ++k) x[std::size_t(k)] *= Lb / Lu;
        }
        // Keep the piece and continue from its end, with its frame.
        const double L = target.arc[b] - target.arc[a];
        HelicoidPiece pc;
        pc.k = {x[0] / L, x[1] / L, x[2] / L, x[3]};
        pc.length = L;
        pc.roll = x.size() > 4 ? x[4] : 0.0;
        fitter.tracePiece(x, L, p0, q, trace, /*exact=*/true);  // chain pieces as they will be grown
        p0 = trace.points.back();
        q = trace.frames.back();
        previous = x;
        for (int k = 0; k < 3; ++k) previous[std::size_t(k)] = previous[std::size_t(k)] / L;  // unscaled for the next start
        fit.pieces.push_back(pc);
        a = b;
    }
    bool carried = false;
    for (std::size_t i = 0; i < fit.pieces.size(); ++i) normalizeSign(fit.pieces[i], i == 0, fit.frame, carried);
    // The whole fit, as grown, against the target densified to the same spacing.
    traceFit(fit, trace);
    densify(target.pts, 0, last, step, denseTarget);
    fit.frechet = discreteFrechet(denseTarget.data(), denseTarget.size(), trace.points.data(), trace.points.size());
    std::size_t pairs = 0;
    const double c = frechetCoupling(denseTarget.data(), denseTarget.size(), trace.points.data(), trace.points.size(), &pairs);
    fit.coupling = c / double(std::max<std::size_t>(1, pairs));
    fit.evaluations = fitter.evaluations;
    return fit;
}

std::vector<StrandFit> fitStrands(const StrandSet& strands, const FitParams& params, bool threaded,
                                  std::vector<std::string>* errors, openvdb::util::NullInterrupter* interrupter)
{
    const FitParams& p = params;
    const std::size_t nS = strands.numStrands();
    std::vector<StrandFit> fits(nS);
    std::vector<std::string> messages(nS);
    ProgressCounter progress(interrupter, "fitting p-helicoids", nS, "strands");
    auto body = [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
            if (progress.stopped()) return;
            try {
                fits[i] = fitStrand(strands.data(i), strands.size(i), p);
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
                         const std::vector<std::string>& errors, double maxError)
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
    }
    s.fitted = relative.size();
    s.pointBytes = double(strands.numVertices()) * 12;
    if (relative.empty()) return s;
    std::vector<double> sorted = relative;
    std::sort(sorted.begin(), sorted.end());
    for (double r : relative) s.meanRelative += r;
    s.meanRelative /= double(relative.size());
    s.p95Relative = sorted[std::size_t(std::ceil(0.95 * double(sorted.size()))) - 1];
    s.overMaxError = std::size_t(sorted.end() - std::upper_bound(sorted.begin(), sorted.end(), maxError));
    s.piecesPerStrand = double(pieces) / double(s.fitted);
    s.fitBytes = double(s.fitted) * (3 + 6) * 4 + double(pieces) * 6 * 4;
    s.evaluationsPerStrand = double(evaluations) / double(s.fitted);
    return s;
}

} // namespace vdbhair
