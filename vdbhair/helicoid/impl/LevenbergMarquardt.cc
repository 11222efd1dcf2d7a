#include "LevenbergMarquardt.h"

#include <vdbhair/Exceptions.h>

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <string>

namespace vdbhair {
namespace fit {

namespace {

Eigen::VectorXd evaluate(LeastSquaresProblem& problem, const std::vector<double>& x)
{
    Eigen::VectorXd r(Eigen::Index(problem.residualCount()));
    problem.residuals(x.data(), x.size(), r.data());
    return r;
}

} // namespace

double residualCost(LeastSquaresProblem& problem, const std::vector<double>& x)
{
    return evaluate(problem, x).squaredNorm();
}

double minimizeLevenbergMarquardt(LeastSquaresProblem& problem, std::vector<double>& x, const LevenbergMarquardtOptions& options)
{
    const std::size_t dims = x.size();
    if (dims < 1 || dims > kMaxUnknowns) {
        throw ValueError("minimizeLevenbergMarquardt: " + std::to_string(dims) + " unknowns; between 1 and " +
                         std::to_string(kMaxUnknowns) + " are supported");
    }
    problem.clamp(x);
    const std::size_t rows = problem.residualCount();
    const Eigen::Index n = Eigen::Index(rows);
    Eigen::VectorXd r(n), rj(n), rn(n);
    problem.residuals(x.data(), dims, r.data());
    double cost = r.squaredNorm();
    double mu = 1e-3;
    if (problem.closeEnough(r.data())) return cost;

    // The Jacobian by forward differences (column-major: column j at J[j * rows]).
    std::vector<double> J(rows * dims);
    std::vector<double> xh(x), xn(x);
    auto jacobian = [&]() {
        for (std::size_t j = 0; j < dims; ++j) {
            xh = x;
            const double h = 1e-6 * std::max(1.0, std::abs(x[j]));
            xh[j] += h;
            problem.residuals(xh.data(), dims, rj.data());
            double* col = &J[j * rows];
            for (std::size_t k = 0; k < rows; ++k) col[k] = (rj[Eigen::Index(k)] - r[Eigen::Index(k)]) / h;
        }
    };
    jacobian();
    bool fresh = true;
    int rejected = 0;
    using Small = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor, kMaxUnknowns, kMaxUnknowns>;
    using SmallVec = Eigen::Matrix<double, Eigen::Dynamic, 1, Eigen::ColMajor, kMaxUnknowns, 1>;
    double A[kMaxUnknowns][kMaxUnknowns], g[kMaxUnknowns], dx[kMaxUnknowns], step[kMaxUnknowns];
    for (int it = 0; it < options.maxIterations; ++it) {
        // The normal equations: A = JᵀJ, g = Jᵀr.
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
        // The damped step dx = -M⁻¹ g with M = A + mu diag(A) (+ a tiny ridge), by LDLᵀ with
        // pivoting: a Cholesky factorization that gives up on nearly dependent columns (a roll
        // that barely moves a nearly straight piece) was measured worse (docs/fitting.md).
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
        problem.clamp(xn);
        double step2 = 0.0;
        for (std::size_t i = 0; i < dims; ++i) {
            step[i] = xn[i] - x[i];
            step2 += step[i] * step[i];
        }
        if (!(step2 > 1e-20)) break;
        problem.residuals(xn.data(), dims, rn.data());
        const double newCost = rn.squaredNorm();
        // Broyden's update from the trial step, accepted or not: J += (rn - r - J step) stepᵀ / |step|².
        if (std::isfinite(newCost)) {
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
            if (gain < options.minGain * cost || problem.closeEnough(r.data())) break;
        } else {
            mu *= 10.0;
            if (fresh && mu > 1e6) break;
            // Broyden's update has taken in the failed step; a second failure in a row
            // refreshes the Jacobian.
            if (!fresh && ++rejected >= 2) { jacobian(); fresh = true; rejected = 0; }
        }
    }
    return cost;
}

} // namespace fit
} // namespace vdbhair
