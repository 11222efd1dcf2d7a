#include "NelderMead.h"

#include <nlopt.hpp>

#include <algorithm>
#include <cmath>
#include <exception>

namespace vdbhair {
namespace fit {

double minimizeNelderMead(const std::function<double(const std::vector<double>&)>& f, std::vector<double>& x,
                          const NelderMeadOptions& options)
{
    nlopt::opt opt(nlopt::LN_NELDERMEAD, unsigned(x.size()));
    opt.set_min_objective(
        [](const std::vector<double>& v, std::vector<double>&, void* data) {
            const double value = (*static_cast<const std::function<double(const std::vector<double>&)>*>(data))(v);
            return std::isfinite(value) ? value : 1e30;
        },
        const_cast<std::function<double(const std::vector<double>&)>*>(&f));
    opt.set_lower_bounds(options.lower);
    opt.set_upper_bounds(options.upper);
    for (std::size_t i = 0; i < x.size(); ++i) x[i] = std::max(options.lower[i], std::min(options.upper[i], x[i]));
    opt.set_initial_step(options.initialStep);
    opt.set_xtol_abs(options.xtolAbs);
    opt.set_ftol_rel(options.ftolRel);
    opt.set_maxeval(options.maxEvaluations);
    double value = 0.0;
    try {
        opt.optimize(x, value);
    } catch (const nlopt::roundoff_limited&) {
        // the best point so far is in x
    } catch (const std::exception&) {
        value = f(x);
    }
    return value;
}

} // namespace fit
} // namespace vdbhair
