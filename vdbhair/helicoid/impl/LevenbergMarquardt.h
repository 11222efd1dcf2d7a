/// @file LevenbergMarquardt.h
/// @brief The fitter's local least-squares solver (HelicoidFit.h's pre-fit): Levenberg–Marquardt
/// with a Jacobian by forward differences once, then Broyden's rank-one updates, for problems of
/// at most kMaxUnknowns unknowns within a box. Internal to the fitter; docs/fitting.md says why.
#pragma once

#include <cstddef>
#include <vector>

namespace vdbhair {
namespace fit {

/// @brief A nonlinear least-squares problem: minimize |r(x)|² over x in a box.
class LeastSquaresProblem
{
public:
    virtual ~LeastSquaresProblem() = default;
    /// @brief How many residuals r(x) has (fixed for the problem).
    virtual std::size_t residualCount() const = 0;
    /// @brief r(x): write residualCount() values to @a r for the unknowns @a x (x.size() of them).
    virtual void residuals(const double* x, std::size_t dims, double* r) = 0;
    /// @brief Move @a x into the feasible box (every trial point passes through it).
    virtual void clamp(std::vector<double>& x) const { (void)x; }
    /// @brief Whether residuals @a r are good enough to stop at once (checked at the start and
    /// after every accepted step).
    virtual bool closeEnough(const double* r) const { (void)r; return false; }
};

struct LevenbergMarquardtOptions
{
    int maxIterations = 10;  ///< trial steps (each one evaluation of r)
    double minGain = 1e-2;   ///< stop when an accepted step lowers |r|² by less than this fraction of it
};

/// Most unknowns minimizeLevenbergMarquardt() takes: its normal equations are formed by hand and
/// solved on the stack (Eigen's general kernels cost as much as a trace at these sizes).
constexpr std::size_t kMaxUnknowns = 5;

/// @brief |r(@a x)|² of @a problem (one evaluation of r, as the solver sums it).
double residualCost(LeastSquaresProblem& problem, const std::vector<double>& x);

/// @brief Minimize |r(x)|² from @a x (clamped first) by Levenberg–Marquardt (Marquardt 1963):
/// damped normal equations (JᵀJ + mu diag(JᵀJ)) dx = -Jᵀr solved by LDLᵀ with pivoting (J's
/// columns can be nearly dependent), mu divided by 0.3 after an accepted step and multiplied by 10
/// after a rejected one. J by forward differences at the start, then Broyden's rank-one update
/// from every trial step (Broyden 1965; one evaluation per iteration instead of dims + 1),
/// recomputed after two rejected steps in a row. The box is kept by projecting every trial point
/// (LeastSquaresProblem::clamp()), not by a constrained solve: where a bound is active the search
/// may stop short of the constrained minimum (the fitter's bounds guard k and alpha, docs/fitting.md).
/// @param[in,out] x the start; on return the best point found (within the box)
/// @return |r(x)|² at the returned x
/// @throw ValueError for more than kMaxUnknowns unknowns or none.
double minimizeLevenbergMarquardt(LeastSquaresProblem& problem, std::vector<double>& x,
                                  const LevenbergMarquardtOptions& options = {});

} // namespace fit
} // namespace vdbhair
