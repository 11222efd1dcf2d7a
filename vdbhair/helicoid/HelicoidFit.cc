#include "HelicoidFit.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/Progress.h>
#include <vdbhair/helicoid/AnalyticHelicoidSampler.h>
#include <vdbhair/helicoid/Frechet.h>
#include <vdbhair/strands/Frames.h>
#include <vdbhair/strands/Measures.h>

#include <Eigen/Dense>
#include <nlopt.hpp>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <functional>
#include <cmath>

namespace vdbhair {

namespace {

Vec3f toF(const Vec3d& v) { return Vec3f(float(v.x()), float(v.y()), float(v.z())); }

/// Helicoid::tangent() with the branchless forms of fastmath's functions (the same polynomials):
/// the pre-fit's traces call it millions of times, and the branches of the scalar forms (the
/// quadrant of sin/cos, the reduction of atan) follow the data.
inline Vec3d prefitTangent(const Helicoid& h, const Vec3d& world, double& thetaRef)
{
    const Vec3d d = world - h.p0;
    const double y1 = d.dot(h.q.t), y2 = d.dot(h.q.n), y3 = d.dot(h.q.b);
    double th = fastmath::atan2Lane(h.k.kT * y1 + h.k.kN * y2, 1.0 + h.k.kN * y1 - h.k.kT * y2) + h.k.kB * y3;
    constexpr double twoPi = 2.0 * M_PI;
    th += twoPi * fastmath::roundLane((thetaRef - th) * (1.0 / twoPi));
    thetaRef = th;
    double ct, st, cp, sp;
    fastmath::sinCosLane(th, st, ct);
    fastmath::sinCosLane(h.k.alpha * th, sp, cp);
    return (cp * ct) * h.q.t + (cp * st) * h.q.n + sp * h.q.b;
}

/// The target strand: distinct points, their arc lengths, and its curvature profile.
struct Target
{
    std::vector<Vec3d> pts;
    std::vector<double> arc;
    std::vector<float> curvature;
    std::vector<Vec3d> normal;  ///< discrete Frenet normals (Frames.h)
    std::vector<double> turning;  ///< turning angle at each vertex (radians; 0 at the ends)
    double length = 0.0;
};

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
    std::vector<Vec3d> points;          // scratch: traced points
    double prefitStop = 0.0;
    /// The target's vertices a..b densified to one spacing, kept while the same fragment is asked for.
    struct DenseFragment
    {
        std::vector<Vec3d> pts;
        std::size_t a = ~std::size_t(0), b = 0;

        const std::vector<Vec3d>& get(const Target& target, std::size_t first, std::size_t last, double spacing)
        {
            if (first != a || last != b) {
                densifyPolyline(target.pts, first, last, spacing, pts);
                a = first;
                b = last;
            }
            return pts;
        }
    };
    DenseFragment denseExact;  ///< at the scene's step
    DenseFragment dense;       ///< at the objective's step (evalStep)

    const std::vector<Vec3d>& exactFragment(std::size_t a, std::size_t b) { return denseExact.get(target, a, b, step); }
    const std::vector<Vec3d>& fragment(std::size_t a, std::size_t b) { return dense.get(target, a, b, evalStep); }

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

    /// The points of tracePiece() at step @a h, without its frames (the same RK4 steps and
    /// arithmetic as tracePHelicoids): what the objective and the acceptance test compare.
    /// @return the trace's clearance: its least distance from the piece's singular axis, in
    /// scene steps (Helicoid::axisDistance; checked at every point traced).
    double tracePoints(const std::vector<double>& x, double L, const Vec3d& p0, const FrameD& q, double h, std::vector<Vec3d>& out) const
    {
        Helicoid hel;
        hel.k = {x[0] / L, x[1] / L, x[2] / L, x[3]};
        hel.q = x.size() > 4 ? q.rolled(x[4]) : q;
        hel.p0 = p0;
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
            Vec3d q;
            rk4.advanceFrom(p, k1, hs, q);
            p = q;
            k1 = sampler.tangent(p);
            out[j + 1] = p;
            clearance = std::min(clearance, hel.axisDistance(p));
        }
        return clearance / step;
    }

    /// Eq. 5's penalty for a trace nearer the singular axis than params.axisClearance scene steps
    /// (0 beyond it): such a trace is a discretization artefact, not a streamline (issue 19).
    double axisPenalty(double clearance) const
    {
        const double c = params.axisClearance;
        return c > 0.0 && clearance < c ? c / std::max(clearance, 1e-3) - 1.0 : 0.0;
    }

    /// Eq. 5, scale-free: the coupling's mean leash over L, plus λ times the turns of the piece.
    double objective(const std::vector<double>& x, std::size_t a, std::size_t b, const Vec3d& p0, const FrameD& q)
    {
        ++evaluations;
        const double L = target.arc[b] - target.arc[a];
        const double clearance = tracePoints(x, L, p0, q, evalStep, points);
        const std::vector<Vec3d>& frag = fragment(a, b);
        std::size_t pairs = 0;
        const double c = frechetCoupling(frag.data(), frag.size(), points.data(), points.size(), &pairs);
        const double turns = std::sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]) / (2.0 * M_PI) + std::abs(x[3]);
        // The end point matters twice: the next piece starts there, and can only bend, not jump.
        const double end = (points.back() - target.pts[b]).length();
        return (c / double(std::max<std::size_t>(1, pairs)) + end) / L + params.lambda * turns + axisPenalty(clearance);
    }

    /// Nelder–Mead from @a start; returns the best x and its objective.
    double minimize(std::vector<double>& x, std::size_t a, std::size_t b, const Vec3d& p0, const FrameD& q, double initialStep)
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
        // alpha within ±3. This holds at the piece's root only (there the singular axis is
        // 1/|k| away); along the trace axisPenalty() and within() keep the distance.
        const double L = target.arc[b] - target.arc[a];
        const double kmax = 1.0 * L / evalStep;
        std::vector<double> lower{-kmax, -kmax, -kmax, -3.0}, upper{kmax, kmax, kmax, 3.0};
        if (x.size() > 4) { lower.push_back(-4.0 * M_PI); upper.push_back(4.0 * M_PI); }
        opt.set_lower_bounds(lower);
        opt.set_upper_bounds(upper);
        for (std::size_t i = 0; i < x.size(); ++i) x[i] = std::max(lower[i], std::min(upper[i], x[i]));
        std::vector<double> stepSizes(x.size(), initialStep);
        if (x.size() > 4) stepSizes[4] = 0.8 * initialStep;
        opt.set_initial_step(stepSizes);
        // Without a pre-fit, the search from the raw starts keeps its tight tolerances.
        const double tol = params.prefitIterations > 0 ? params.polishTolerance : 1e-4;
        opt.set_xtol_abs(tol);
        opt.set_ftol_rel(tol * 1e-3);
        opt.set_maxeval(params.prefitIterations > 0 ? params.polishEvaluations : params.maxEvaluations);
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

    /// The piece with scaled parameters @a x traced from (p0, q) at the fragment's own arc
    /// lengths: out[i] is where target vertex a + i should be (one step of Kutta's third-order rule
    /// or of RK4, `prefitOrder`, per target segment, subdivided to at most the objective's step).
    void traceAtVertices(const double* x, std::size_t dims, std::size_t a, std::size_t b, const Vec3d& p0, const FrameD& q,
                         std::vector<Vec3d>& out, Vec3d* endTangent = nullptr) const
    {
        const double L = target.arc[b] - target.arc[a];
        Helicoid h;
        h.k = {x[0] / L, x[1] / L, x[2] / L, x[3]};
        h.q = dims > 4 ? q.rolled(x[4]) : q;
        h.p0 = p0;
        out.resize(b - a + 1);
        Vec3d p = p0;
        double th = h.theta(p, 0.0);
        Vec3d k1 = h.frameFromTheta(th).t;
        out[0] = p;
        auto advance = [&](double hs) {
            if (params.prefitOrder == 3) {
                // Kutta's third-order rule: one tangent fewer per step (the last one is the next
                // step's first).
                double t2 = th, t3 = th;
                const Vec3d k2 = prefitTangent(h, p + 0.5 * hs * k1, t2);
                const Vec3d k3 = prefitTangent(h, p + hs * (2.0 * k2 - k1), t3);
                p += (hs / 6.0) * (k1 + 4.0 * k2 + k3);
                k1 = prefitTangent(h, p, th);
                return;
            }
            double t2 = th, t3 = th, t4 = th;
            const Vec3d k2 = prefitTangent(h, p + 0.5 * hs * k1, t2);
            const Vec3d k3 = prefitTangent(h, p + 0.5 * hs * k2, t3);
            const Vec3d k4 = prefitTangent(h, p + hs * k3, t4);
            p += (hs / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
            k1 = prefitTangent(h, p, th);
        };
        // Where the strand turns slowly, one step spans several segments (the strand turning
        // at most prefitMaxTurn over them: the steps depend on the fragment only, so the traced
        // positions stay smooth in x for the Jacobian), and the vertices inside it are cubic
        // Hermite interpolants of the step's ends (positions and unit tangents), O(h^4).
        for (std::size_t i = a; i < b;) {
            std::size_t j = i + 1;
            double len = target.arc[j] - target.arc[i];
            double turn = target.turning[i] + target.turning[j];
            while (j < b && j - i < 4 && (turn += target.turning[j + 1]) <= params.prefitMaxTurn) len = target.arc[++j] - target.arc[i];
            if (j == i + 1) {
                const int n = std::max(1, int(std::ceil(len / evalStep - 0.5)));
                for (int m = 0; m < n; ++m) advance(len / n);
            } else {
                const Vec3d pa = p, ta = k1;
                advance(len);
                for (std::size_t m = i + 1; m < j; ++m) {
                    const double u = (target.arc[m] - target.arc[i]) / len, u2 = u * u, u3 = u2 * u;
                    out[m - a] = (2 * u3 - 3 * u2 + 1) * pa + ((u3 - 2 * u2 + u) * len) * ta + (-2 * u3 + 3 * u2) * p +
                                 ((u3 - u2) * len) * k1;
                }
            }
            out[j - a] = p;
            i = j;
        }
        if (endTangent) *endTangent = k1;
    }

    /// Residuals of the arc-length correspondence (the pre-fit's smooth least-squares stand-in
    /// for Eq. 5): (trace(s_i) - h_i) / (L sqrt(n)) for each vertex after the first, the end
    /// point again with weight 1 (the objective counts it twice), and a small Tikhonov term on k.
    void residuals(const double* x, std::size_t dims, std::size_t a, std::size_t b, const Vec3d& p0, const FrameD& q,
                   Eigen::VectorXd& r)
    {
        ++evaluations;
        Vec3d endT;
        traceAtVertices(x, dims, a, b, p0, q, lmTrace, &endT);
        const std::size_t n = b - a;
        const double L = target.arc[b] - target.arc[a];
        const double w = 1.0 / (L * std::sqrt(double(n)));
        r.resize(Eigen::Index(3 * n + 3 + 4 + 3 + 1));
        for (std::size_t i = 1; i <= n; ++i) {
            const Vec3d d = (lmTrace[i] - target.pts[a + i]) * w;
            for (int c = 0; c < 3; ++c) r[Eigen::Index(3 * (i - 1) + std::size_t(c))] = d[c];
        }
        const Vec3d e = (lmTrace[n] - target.pts[b]) / L;
        for (int c = 0; c < 3; ++c) r[Eigen::Index(3 * n + std::size_t(c))] = e[c];
        const double reg = std::sqrt(params.lambda) * 0.1;
        for (int c = 0; c < 4; ++c) r[Eigen::Index(3 * n + 3 + std::size_t(c))] = reg * x[c];
        // The end direction: the next piece starts with this piece's end frame (C¹), so a
        // piece leaving the strand at an angle hands its successor a detour.
        const std::size_t last = target.pts.size() - 1;
        const Vec3d dir = (target.pts[std::min(b + 1, last)] - target.pts[b - 1]).unitSafe();
        const Vec3d et = (endT - dir) * params.endTangentWeight;
        for (int c = 0; c < 3; ++c) r[Eigen::Index(3 * n + 7 + std::size_t(c))] = et[c];
        // Keep away from the singular axis (at the vertices; acceptance checks every step), so
        // that the pre-fit does not settle on a discretization artefact that acceptance refuses.
        double clearance = std::numeric_limits<double>::infinity();
        if (params.axisClearance > 0.0) {
            Helicoid h;
            h.k = {x[0] / L, x[1] / L, x[2] / L, x[3]};
            h.q = dims > 4 ? q.rolled(x[4]) : q;
            h.p0 = p0;
            for (const Vec3d& p : lmTrace) clearance = std::min(clearance, h.axisDistance(p));
        }
        r[Eigen::Index(3 * n + 10)] = params.prefitAxisWeight * axisPenalty(clearance / step);
    }

    /// Levenberg–Marquardt on residuals() from @a x (forward-difference Jacobian), within the
    /// same bounds as the Nelder–Mead search. A few traces per iteration instead of hundreds of
    /// Nelder–Mead evaluations: it finds the basin; Nelder–Mead on Eq. 5 then polishes.
    double prefit(std::vector<double>& x, std::size_t a, std::size_t b, const Vec3d& p0, const FrameD& q)
    {
        const std::size_t dims = x.size();
        const double L = target.arc[b] - target.arc[a];
        const double kmax = 1.0 * L / evalStep;
        auto clamp = [&](std::vector<double>& v) {
            for (std::size_t i = 0; i < 3; ++i) v[i] = std::max(-kmax, std::min(kmax, v[i]));
            v[3] = std::max(-3.0, std::min(3.0, v[3]));
            if (dims > 4) v[4] = std::max(-4.0 * M_PI, std::min(4.0 * M_PI, v[4]));
        };
        clamp(x);
        Eigen::VectorXd r, rj, rn;
        residuals(x.data(), dims, a, b, p0, q, r);
        double cost = r.squaredNorm();
        double mu = 1e-3;
        // Good enough: every vertex within prefitStop of its arc-length counterpart.
        const double wv = 1.0 / (L * std::sqrt(double(b - a)));
        auto closeEnough = [&](const Eigen::VectorXd& v) {
            if (!(prefitStop > 0.0)) return false;
            const double lim = prefitStop * prefitStop * wv * wv;
            for (std::size_t i = 0; i < b - a; ++i) {
                const double d2 = v[Eigen::Index(3 * i)] * v[Eigen::Index(3 * i)] + v[Eigen::Index(3 * i + 1)] * v[Eigen::Index(3 * i + 1)] +
                                  v[Eigen::Index(3 * i + 2)] * v[Eigen::Index(3 * i + 2)];
                if (d2 > lim) return false;
            }
            return true;
        };
        if (closeEnough(r)) return cost;
        // At most 5 parameters: the normal equations are formed by hand and solved on the stack,
        // rather than with Eigen's general (large-matrix) kernels, which cost as much as a trace
        // at these sizes.
        const std::size_t rows = std::size_t(r.size());
        std::vector<double> J(rows * dims);  // column-major: column j at J[j * rows]
        std::vector<double> xh(x), xn(x);
        // The Jacobian by forward differences, then Broyden's rank-one updates from every trial
        // step (one trace per iteration instead of dims + 1); recomputed when a step fails.
        auto jacobian = [&]() {
            for (std::size_t j = 0; j < dims; ++j) {
                xh = x;
                const double h = 1e-6 * std::max(1.0, std::abs(x[j]));
                xh[j] += h;
                residuals(xh.data(), dims, a, b, p0, q, rj);
                double* col = &J[j * rows];
                for (std::size_t k = 0; k < rows; ++k) col[k] = (rj[Eigen::Index(k)] - r[Eigen::Index(k)]) / h;
            }
        };
        jacobian();
        bool fresh = true;
        int rejected = 0;
        using Small = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor, 5, 5>;
        using SmallVec = Eigen::Matrix<double, Eigen::Dynamic, 1, Eigen::ColMajor, 5, 1>;
        double A[5][5], g[5], dx[5], step[5];
        for (int it = 0; it < params.prefitIterations; ++it) {
            for (std::size_t i = 0; i < dims; ++i) {
                const double* ci = &J[i * rows];
                for (std::size_t j = 0; j <= i; ++j) {
                    const double* cj = &J[j * rows];
                    double sum = 0.0;
                    for (std::size_t k = 0; k < rows; ++k) sum += ci[k] * cj[k];
                    A[i][j] = A[j][i] = sum;
                }
                double sum = 0.0;
                for (std::size_t k = 0; k < rows; ++k) sum += ci[k] * r[Eigen::Index(k)];
                g[i] = sum;
            }
            // dx = -M⁻¹ g with M = A + mu diag(A) (+ a tiny ridge), by LDLᵀ with pivoting: J's
            // columns can be nearly dependent (a roll that barely moves a nearly straight piece),
            // and a Cholesky factorization that gives up there was measured worse (wavy at the
            // former defaults: 3.30 % instead of 3.01 %).
            Small M(dims, dims);
            SmallVec rhs(dims);
            for (std::size_t i = 0; i < dims; ++i) {
                rhs[Eigen::Index(i)] = -g[i];
                for (std::size_t j = 0; j < dims; ++j) M(Eigen::Index(i), Eigen::Index(j)) = A[i][j];
                M(Eigen::Index(i), Eigen::Index(i)) += mu * (A[i][i] + 1e-9);
            }
            const SmallVec sol = M.ldlt().solve(rhs);
            for (std::size_t i = 0; i < dims; ++i) dx[i] = sol[Eigen::Index(i)];
            for (std::size_t i = 0; i < dims; ++i) xn[i] = x[i] + dx[i];
            clamp(xn);
            double step2 = 0.0;
            for (std::size_t i = 0; i < dims; ++i) {
                step[i] = xn[i] - x[i];
                step2 += step[i] * step[i];
            }
            if (!(step2 > 1e-20)) break;
            residuals(xn.data(), dims, a, b, p0, q, rn);
            const double newCost = rn.squaredNorm();
            if (params.broyden && std::isfinite(newCost)) {
                // J += (rn - r - J step) stepᵀ / |step|²
                for (std::size_t k = 0; k < rows; ++k) {
                    double u = rn[Eigen::Index(k)] - r[Eigen::Index(k)];
                    for (std::size_t j = 0; j < dims; ++j) u -= J[j * rows + k] * step[j];
                    u /= step2;
                    for (std::size_t j = 0; j < dims; ++j) J[j * rows + k] += u * step[j];
                }
            }
            if (std::isfinite(newCost) && newCost < cost) {
                const double gain = cost - newCost;
                x = xn;
                r = rn;
                cost = newCost;
                mu = std::max(1e-9, mu * 0.3);
                fresh = false;
                rejected = 0;
                if (!params.broyden) { jacobian(); fresh = true; }
                if (gain < params.prefitGain * cost || closeEnough(r)) break;
            } else {
                mu *= 10.0;
                if (fresh && mu > 1e6) break;
                // Broyden's update has taken in the failed step; a second failure in a row
                // refreshes the Jacobian.
                if (!fresh && (!params.broyden || ++rejected >= 2)) { jacobian(); fresh = true; rejected = 0; }
            }
        }
        return cost;
    }

    /// Fit one piece to the fragment [a, b] from (p0, q); q fixed (a roll may be fitted).
    /// @param hint optional: a fit of a neighbouring fragment [a, c], scaled by its length @a hintLength
    std::vector<double> fitPiece(std::size_t a, std::size_t b, const Vec3d& p0, const FrameD& q, const std::vector<double>* previous,
                                 bool allowRoll, bool thorough, bool polish, const std::vector<double>* hint = nullptr,
                                 double hintLength = 0.0, int startsToRun = 0,
                                 const std::function<bool(const std::vector<double>&)>& good = nullptr)
    {
        const double L = target.arc[b] - target.arc[a];
        const std::size_t dims = allowRoll ? 5 : 4;
        std::vector<std::vector<double>> starts;
        // The strand's curvature and torsion near the start, with the frame rolled so that its
        // normal is the strand's Frenet normal there. A search candidate with a neighbouring
        // fit to start from (@a hint) pre-fits from that alone.
        if (!(hint && !thorough && params.prefitIterations > 0)) {
            double kappa, tau;
            startEstimate(a, b, kappa, tau);
            starts.push_back({kappa * L, 0.0, 0.0, kappa > 1e-9 ? std::max(-2.0, std::min(2.0, tau / kappa)) : 0.0});
            if (allowRoll) {
                const Vec3d& n = target.normal[a];
                starts.back().push_back(std::atan2(n.dot(q.b), n.dot(q.n)));
            }
        }
        if (hint) {
            std::vector<double> h = *hint;
            for (int k = 0; k < 3; ++k) h[std::size_t(k)] *= L / hintLength;
            starts.push_back(h);
        }
        if (thorough) starts.push_back({0.0, 0.0, 0.0, 0.0});
        if (previous && thorough) starts.push_back({(*previous)[0] * L, (*previous)[1] * L, (*previous)[2] * L, (*previous)[3]});
        std::vector<double> best;
        double bestF = std::numeric_limits<double>::max();
        if (params.prefitIterations > 0) {
            // Pre-fit from the starts that the smooth objective ranks first.
            const std::size_t maxRuns = std::size_t(std::max(1, startsToRun > 0 ? startsToRun : params.prefitStarts));
            std::vector<std::pair<double, std::size_t>> ranked;
            Eigen::VectorXd r;
            for (std::size_t i = 0; i < starts.size(); ++i) {
                starts[i].resize(dims, 0.0);
                if (starts.size() > maxRuns) residuals(starts[i].data(), dims, a, b, p0, q, r);
                ranked.emplace_back(starts.size() > maxRuns ? r.squaredNorm() : 0.0, i);
            }
            if (ranked.size() > 1) std::sort(ranked.begin(), ranked.end());
            const std::size_t runs = std::min(ranked.size(), maxRuns);
            for (std::size_t i = 0; i < runs; ++i) {
                std::vector<double> x = starts[ranked[i].second];
                const double f = prefit(x, a, b, p0, q);
                if (f < bestF) { bestF = f; best = x; }
                // The first pre-fit that is good enough ends the search (in the starts' order).
                if (good && i + 1 < runs && good(x)) { best = x; break; }
            }
        } else {
            for (std::vector<double> x : starts) {
                x.resize(dims, 0.0);
                const double f = objective(x, a, b, p0, q);
                if (f < bestF) { bestF = f; best = x; }
            }
        }
        // Nelder–Mead from the most promising start only.
        if (polish) minimize(best, a, b, p0, q, params.prefitIterations > 0 ? params.polishStep : 0.5);
        return best;  // scaled by this fragment's L
    }

    /// Nelder–Mead on Eq. 5 from a pre-fit @a x of [a, b].
    void polish(std::vector<double>& x, std::size_t a, std::size_t b, const Vec3d& p0, const FrameD& q)
    {
        minimize(x, a, b, p0, q, params.polishStep);
    }

    std::vector<Vec3d> lmTrace;  // scratch
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
    std::vector<Frame> frames(f.size());
    if (!f.empty()) frenetFrames(f.data(), f.size(), frames.data());
    t.turning.assign(t.pts.size(), 0.0);
    for (std::size_t i = 1; i + 1 < t.pts.size(); ++i) {
        const Vec3d u = (t.pts[i] - t.pts[i - 1]).unitSafe(), v = (t.pts[i + 1] - t.pts[i]).unitSafe();
        t.turning[i] = std::atan2(u.cross(v).length(), u.dot(v));
    }
    t.normal.resize(f.size());
    for (std::size_t i = 0; i < f.size(); ++i) t.normal[i] = Vec3d(frames[i].n);
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

    // A fit with more floats than the points it replaces is pointless: 9 floats per strand and
    // 6 per piece against 3 per vertex.
    int maxPieces = params.maxPieces;
    if (params.capByPoints) maxPieces = std::max(1, std::min(maxPieces, (3 * int(std::min<std::size_t>(n, 1 << 20)) - 10) / 6));
    const double minLength = std::max(params.minFragment * target.length, 1e-12);
    const bool forward = params.forwardSearch && params.prefitIterations > 0;
    HelicoidTrace trace;
    std::vector<Vec3d> denseTarget;

    // The pieces (§5.3) accepted within @a tolerance (world units), into f.pieces.
    bool keepClear = false;  // every piece kept clear of its axis (the refit of an unconverged fit)
    auto fitPieces = [&](double tolerance, StrandFit& f) {
        f.pieces.clear();
        std::size_t a = 0;
        Vec3d p0 = f.root;
        FrameD q = f.frame;
        std::vector<double> previous;
        double previousTurn = 0.0;  // turning of the previous piece's upper limit (the forward search's first guess)
        while (a < last) {
            const bool allowRoll = params.optimizeRoll;
            const double remaining = target.length - target.arc[a];
            // Is the fit x of [a, b], as grown, within @a eps of the fragment (discrete Fréchet)?
            auto within = [&](std::size_t b, const std::vector<double>& x, double eps) {
                const double L = target.arc[b] - target.arc[a];
                std::vector<Vec3d>& pts = fitter.points;
                // A trace near the singular axis changes with the step: not a streamline.
                if (fitter.tracePoints(x, L, p0, q, step, pts) < params.axisClearance) return false;
                if (b < last && (pts.back() - target.pts[b]).length() > params.acceptEndOffset * eps) return false;
                const std::vector<Vec3d>& frag = fitter.exactFragment(a, b);
                return discreteFrechetWithin(frag.data(), frag.size(), pts.data(), pts.size(), eps);
            };
            // A candidate fit of [a, b]: pre-fitted from the starts (and @a hint, a fit of [a, hb]);
            // polished by Nelder–Mead on Eq. 5 only when @a polish (the search for the split
            // compares pre-fits; the piece kept is polished).
            auto fitTo = [&](std::size_t b, std::vector<double>& x, bool thorough, bool polish, const std::vector<double>* hint = nullptr,
                             std::size_t hb = 0, int startsToRun = 0) {
                int verdict = -1;  // the last pre-fit's acceptance, when known
                std::function<bool(const std::vector<double>&)> good;
                if (!polish && params.firstGoodStart) {
                    good = [&](const std::vector<double>& y) {
                        verdict = within(b, y, tolerance) ? 1 : 0;
                        return verdict == 1;
                    };
                }
                fitter.prefitStop = polish ? 0.0 : params.prefitStopFraction * tolerance;
                x = fitter.fitPiece(a, b, p0, q, previous.empty() ? nullptr : &previous, allowRoll, thorough, polish, hint,
                                    hint ? target.arc[hb] - target.arc[a] : 0.0, startsToRun, good);
                return verdict == 1 ? true : within(b, x, tolerance);
            };
            // Polish a pre-fit (@a ok: it is acceptable); a polish that makes an acceptable fit
            // unacceptable is undone (Eq. 5 weighs the mean leash, the acceptance its maximum).
            auto polishFit = [&](std::size_t b, std::vector<double>& x, bool ok) {
                if (params.polishEvaluations <= 0) return ok;
                std::vector<double> y = x;
                fitter.polish(y, a, b, p0, q);
                const bool okAfter = within(b, y, tolerance);
                if (okAfter || !ok) { x = y; return okAfter; }
                return ok;
            };
            const bool searchWithoutPolish = params.prefitIterations > 0;
            std::vector<double> x;
            std::size_t b = last;
            const bool lastPiece = int(f.pieces.size()) + 1 >= maxPieces || remaining < 2.0 * minLength || last - a < 3;
            // The search for the split's upper limit u (the longest acceptable prefix) and its fit.
            std::size_t u = last;
            std::vector<double> xu;
            bool okU = false, split = false;
            if (forward && !lastPiece) {
                // Forward search: candidates [a, b] with b in [lo, hiMax] (leaving at least the
                // minimum fragment) or the whole remainder. The first candidate ends where the strand
                // has turned as much as the previous piece's limit did (searchTurn for the first
                // piece): gallop up from an acceptable candidate by growth, down by halves from an
                // unacceptable one, then bisect. Each candidate starts from the nearest fit found.
                const std::size_t lo = std::min(last, std::max(a + 2, indexAtArc(target, target.arc[a] + minLength)));
                std::size_t hiMax = last;
                while (hiMax > a && (last - hiMax < 2 || target.arc[last] - target.arc[hiMax] < minLength)) --hiMax;
                auto snap = [&](std::size_t c) { return c > hiMax ? last : std::max(c, lo); };
                const double budget = previousTurn > 0.0 ? previousTurn : params.searchTurn;
                std::size_t g = a + 1;
                for (double turned = 0.0; g < last && turned + target.turning[g] <= budget; ++g) turned += target.turning[g];
                const bool polish = !searchWithoutPolish;
                std::size_t good = a, bad = last + 1, c = snap(g);
                std::vector<double> xg, xb, xt;
                // The whole remainder, as the paper's first fit of a fragment: a pre-fit close to
                // acceptable is polished on Eq. 5 before it is judged.
                bool polishedLast = false;
                auto judgeLast = [&](std::size_t cand, std::vector<double>& y, bool ok) {
                    if (ok || cand != last || !searchWithoutPolish || !within(last, y, params.polishMargin * tolerance)) return ok;
                    polishedLast = true;
                    return polishFit(last, y, false);
                };
                bool okC = judgeLast(c, xt, fitTo(c, xt, true, polish, nullptr, 0, c == last ? params.lastPieceStarts : 0));
                (okC ? good : bad) = c;
                (okC ? xg : xb) = xt;
                if (okC) {
                    while (good < last) {
                        c = snap(a + std::size_t(std::ceil(double(good - a) * params.searchGrowth)));
                        if (judgeLast(c, xt, fitTo(c, xt, false, polish, &xg, good))) { good = c; xg = xt; }
                        else { bad = c; xb = xt; break; }
                    }
                } else {
                    while (bad > lo) {
                        c = std::max(lo, a + (bad - a) / 2);
                        if (fitTo(c, xt, c == lo, polish, &xb, bad)) { good = c; xg = xt; break; }
                        bad = c;
                        xb = xt;
                    }
                }
                if (good > a) {
                    // Bisect between the longest acceptable and the shortest unacceptable candidate
                    // (below the minimum remainder when the whole remainder failed).
                    std::size_t top = bad == last ? hiMax + 1 : bad;
                    const std::size_t resolution = std::size_t(std::max(1.0, params.splitResolution * double(last - a)));
                    while (top > good + resolution) {
                        const std::size_t mid = (good + top) / 2;
                        const bool nearGood = mid - good <= top - mid || xb.empty();
                        if (fitTo(mid, xt, false, polish, nearGood ? &xg : &xb, nearGood ? good : bad)) { good = mid; xg = xt; }
                        else { top = bad = mid; xb = xt; }
                    }
                    u = good;
                    xu = xg;
                    okU = true;
                } else {
                    u = lo;
                    xu = xb;
                }
                if (searchWithoutPolish && !(u == last && polishedLast)) okU = polishFit(u, xu, okU);
                split = u < last;
                if (!split) x = xu;
            } else {
                // The last piece allowed is kept whatever its error: it gets every start.
                bool ok = fitTo(last, x, true, !searchWithoutPolish, nullptr, 0, lastPiece ? params.lastPieceStarts : 0);
                if (searchWithoutPolish && (lastPiece || ok || within(last, x, params.polishMargin * tolerance))) ok = polishFit(last, x, ok);
                split = !ok && !lastPiece;
            }
            if (split && !forward) {
                // Upper limit: the longest prefix whose fit is acceptable (the paper's Fréchet
                // threshold), by bisection over the vertices between the minimum fragment and the
                // remainder (which failed above), starting at the splitFraction of the remainder.
                // Each candidate starts from the nearest fit found so far.
                const std::size_t lo = std::min(last - 1, std::max(a + 2, indexAtArc(target, target.arc[a] + minLength)));
                std::size_t hi = std::min(last - 1, std::max(lo, indexAtArc(target, target.arc[a] + params.splitFraction * remaining)));
                const bool thorough = !searchWithoutPolish;
                const bool polish = !searchWithoutPolish;
                std::vector<double> xt, xb = x;
                std::size_t good = lo, bad = last;
                u = lo;
                if (hi > lo && fitTo(hi, xt, thorough, polish, &xb, last)) {
                    good = hi;
                    xu = xt;
                    okU = true;
                } else {
                    if (hi > lo) { bad = hi; xb = xt; }
                    okU = fitTo(lo, xu, true, polish, hi > lo ? &xb : nullptr, bad);
                }
                if (okU) {
                    const std::size_t resolution = std::size_t(std::max(1.0, params.splitResolution * double(last - a)));
                    while (bad - good > resolution) {
                        const std::size_t mid = (good + bad) / 2;
                        const bool nearGood = mid - good <= bad - mid;
                        if (fitTo(mid, xt, thorough, polish, nearGood ? &xu : &xb, nearGood ? good : bad)) { good = mid; xu = xt; }
                        else { bad = mid; xb = xt; }
                    }
                    u = good;
                }
                if (searchWithoutPolish) polishFit(u, xu, okU);
            }
            if (split) {
                previousTurn = 0.0;
                for (std::size_t v = a + 1; v < u; ++v) previousTurn += target.turning[v];
                // Backtrack from u along the curvature profile to where fragment and fit agree best:
                // in curvature (the paper's criterion) and, since the next piece starts there, in
                // position and direction.
                const double Lu = target.arc[u] - target.arc[a];
                fitter.tracePiece(xu, Lu, p0, q, trace);
                std::vector<Vec3f> tf(trace.points.size());
                for (std::size_t i = 0; i < tf.size(); ++i) tf[i] = toF(trace.points[i]);
                std::vector<float> fitCurv(tf.size());
                curvatureProfile(tf.data(), tf.size(), fitCurv.data());
                std::size_t cut = u;
                double bestScore = std::numeric_limits<double>::max();
                // A fit that ends on the strand, in its direction, keeps its whole length: backtracking
                // exists for the fits that drift near their end.
                const double endOffset = (trace.points.back() - target.pts[u]).length();
                const double endAngle = std::acos(std::max(-1.0, std::min(1.0, trace.frames.back().t.dot((target.pts[u] - target.pts[u - 1]).unitSafe()))));
                const bool keepU = endOffset < params.keepOffset * tolerance && endAngle < params.keepAngle;
                // The window: the last 40 % of the piece (backtracking adjusts the split; it must not
                // throw away the length the bisection found acceptable).
                const double windowStart = std::max(target.arc[a] + minLength, target.arc[u] - params.backtrackWindow * (target.arc[u] - target.arc[a]));
                for (std::size_t v = u; !keepU && v > a + 1 && target.arc[v] >= windowStart; --v) {
                    const double s = target.arc[v] - target.arc[a];
                    const std::size_t m = std::min(tf.size() - 1, std::size_t(std::lround(s / fitter.evalStep)));
                    const Vec3d targetDir = (target.pts[std::min(v + 1, last)] - target.pts[v - 1]).unitSafe();
                    const double angle = std::acos(std::max(-1.0, std::min(1.0, trace.frames[m].t.dot(targetDir))));
                    const double score = std::abs(double(target.curvature[v]) - double(fitCurv[m])) * target.length + angle / 0.05;
                    if (score < bestScore) { bestScore = score; cut = v; }
                }
                b = cut;
                x = xu;
                // The piece fitted to [a, u], kept up to the split (the scaled x refer to Lu).
                const double Lb = target.arc[b] - target.arc[a];
                for (int k = 0; k < 3; ++k) x[std::size_t(k)] *= Lb / Lu;
            }
            // Keep the piece and continue from its end, with its frame.
            const double L = target.arc[b] - target.arc[a];
            // A piece kept without passing within() (the last piece allowed, or no acceptable
            // candidate) may still step near its singular axis. When the fit is redone for that
            // (keepClear), its curvatures are scaled down until its trace keeps its distance
            // (k -> 0 moves the axis away as 1/|k|): a streamline, if a worse one. Not always:
            // most such pieces are streamlines still (measured on wavy: 1.73 % -> 1.88 % mean).
            for (int shrink = 0; shrink < 30 && keepClear && fitter.tracePoints(x, L, p0, q, step, fitter.points) < params.axisClearance;
                 ++shrink) {
                for (int k = 0; k < 3; ++k) x[std::size_t(k)] *= 0.8;
            }
            HelicoidPiece pc;
            pc.k = {x[0] / L, x[1] / L, x[2] / L, x[3]};
            pc.length = L;
            pc.roll = x.size() > 4 ? x[4] : 0.0;
            fitter.tracePiece(x, L, p0, q, trace, /*exact=*/true);  // chain pieces as they will be grown
            p0 = trace.points.back();
            q = trace.frames.back();
            previous = x;
            for (int k = 0; k < 3; ++k) previous[std::size_t(k)] = previous[std::size_t(k)] / L;  // unscaled for the next start
            f.pieces.push_back(pc);
            a = b;
        }
    };
    // The whole fit, as grown, against the target densified to the same spacing.
    densifyPolyline(target.pts, 0, last, step, denseTarget);
    auto measure = [&](StrandFit& f) {
        traceFit(f, trace);
        f.frechet = discreteFrechet(denseTarget.data(), denseTarget.size(), trace.points.data(), trace.points.size());
    };
    const double tolerance = params.maxError * target.length;
    auto fitWithRetries = [&]() {
        StrandFit f = fit;  // root, frame, step, length
        fitPieces(tolerance, f);
        measure(f);
        // A strand that needs more pieces than it may have ends in a long last piece, however far
        // it strays: refit with a larger tolerance (longer pieces) and keep the closest fit.
        for (int retry = 1; retry <= params.relaxRetries && f.frechet > tolerance && int(f.pieces.size()) >= maxPieces; ++retry) {
            StrandFit relaxed = f;
            fitPieces(tolerance * std::pow(params.relaxFactor, retry), relaxed);
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
        keepClear = true;
        StrandFit clear = fitWithRetries();
        keepClear = false;
        if (clear.stepDeviation < best.stepDeviation) best = clear;
    }
    fit = best;
    bool carried = false;
    for (std::size_t i = 0; i < fit.pieces.size(); ++i) normalizeSign(fit.pieces[i], i == 0, fit.frame, carried);
    traceFit(fit, trace);
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
    std::vector<double> sorted = relative;
    std::sort(sorted.begin(), sorted.end());
    for (double r : relative) s.meanRelative += r;
    s.meanRelative /= double(relative.size());
    s.stepDeviationMean /= double(relative.size());
    s.p95Relative = sorted[std::size_t(std::ceil(0.95 * double(sorted.size()))) - 1];
    s.overMaxError = std::size_t(sorted.end() - std::upper_bound(sorted.begin(), sorted.end(), maxError));
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
