/// @file NelderMead.h
/// @brief The fitter's derivative-free local solver (HelicoidFit.h, Eq. 5): NLopt's Nelder–Mead
/// simplex (Nelder & Mead 1965) within a box. Internal to the fitter.
#pragma once

#include <functional>
#include <vector>

namespace vdbhair {
namespace fit {

struct NelderMeadOptions
{
    std::vector<double> lower, upper;  ///< the box, one bound per unknown
    std::vector<double> initialStep;   ///< the initial simplex's step per unknown
    double xtolAbs = 1e-4;             ///< stop when a step moves every unknown by less than this
    double ftolRel = 1e-7;             ///< ... or changes f by less than this fraction
    int maxEvaluations = 300;          ///< most evaluations of f
};

/// @brief Minimize @a f from @a x (moved into the box first) by NLopt's LN_NELDERMEAD. A
/// non-finite f counts as 1e30. Round-off ends the search with the best point so far; any other
/// failure of NLopt leaves @a x where it stopped and returns f there (one more evaluation).
/// @param[in,out] x the start; on return the best point found
/// @return f at the returned x
double minimizeNelderMead(const std::function<double(const std::vector<double>&)>& f, std::vector<double>& x,
                          const NelderMeadOptions& options);

} // namespace fit
} // namespace vdbhair
