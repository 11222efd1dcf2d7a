// The fitter's local solvers (vdbhair/helicoid/impl/LevenbergMarquardt.h, NelderMead.h) on
// problems with closed-form minima.
#include "../TestUtil.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/helicoid/impl/LevenbergMarquardt.h>
#include <vdbhair/helicoid/impl/NelderMead.h>

#include <cmath>
#include <limits>

using namespace vdbhair;
using namespace vdbhair::fit;

namespace {

/// r(x) = A x - y for a 3 x 2 matrix A: the minimum of |r|² solves the normal equations.
struct LinearProblem : LeastSquaresProblem
{
    double A[3][2] = {{1.0, 2.0}, {0.5, -1.0}, {3.0, 0.25}};
    double y[3] = {1.0, -2.0, 0.5};
    double lo = -1e9, hi = 1e9;  // the box on x[1]
    int evaluations = 0;
    std::size_t residualCount() const override { return 3; }
    void residuals(const double* x, std::size_t, double* r) override
    {
        ++evaluations;
        for (int i = 0; i < 3; ++i) r[i] = A[i][0] * x[0] + A[i][1] * x[1] - y[i];
    }
    void clamp(std::vector<double>& x) const override { x[1] = std::max(lo, std::min(hi, x[1])); }
};

/// Rosenbrock's function as residuals: r = (10 (x1 - x0²), 1 - x0), minimum 0 at (1, 1).
struct Rosenbrock : LeastSquaresProblem
{
    std::size_t residualCount() const override { return 2; }
    void residuals(const double* x, std::size_t, double* r) override
    {
        r[0] = 10.0 * (x[1] - x[0] * x[0]);
        r[1] = 1.0 - x[0];
    }
};

} // namespace

TEST_CASE("minimizeLevenbergMarquardt: a linear problem reaches the normal equations' solution", "[helicoid]")
{
    LinearProblem p;
    // The closed form: (AᵀA) x = Aᵀy, 2 x 2.
    double M[2][2] = {{0, 0}, {0, 0}}, g[2] = {0, 0};
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 2; ++j) {
            g[j] += p.A[i][j] * p.y[i];
            for (int k = 0; k < 2; ++k) M[j][k] += p.A[i][j] * p.A[i][k];
        }
    }
    const double det = M[0][0] * M[1][1] - M[0][1] * M[1][0];
    const double x0 = (M[1][1] * g[0] - M[0][1] * g[1]) / det, x1 = (M[0][0] * g[1] - M[1][0] * g[0]) / det;
    std::vector<double> x{5.0, -7.0};
    LevenbergMarquardtOptions o;
    o.maxIterations = 50;
    o.minGain = 0.0;
    const double cost = minimizeLevenbergMarquardt(p, x, o);
    CAPTURE(x[0], x[1], x0, x1);
    REQUIRE(x[0] == Approx(x0).margin(1e-6));
    REQUIRE(x[1] == Approx(x1).margin(1e-6));
    REQUIRE(cost == Approx(residualCost(p, x)).epsilon(1e-12));

    // With the optimum outside the box on x[1], every trial point is projected into it: the
    // result is on the bound, and no worse than the start (the projection is no constrained
    // solve: along the bound it may stop short of the constrained minimum, so x[0] is not checked).
    LinearProblem boxed;
    boxed.hi = x1 - 0.5;
    std::vector<double> xb{0.0, 0.0};
    const double boxedCost = minimizeLevenbergMarquardt(boxed, xb, o);
    REQUIRE(xb[1] == boxed.hi);
    REQUIRE(boxedCost == Approx(residualCost(boxed, xb)).epsilon(1e-12));
    REQUIRE(boxedCost < residualCost(boxed, {0.0, 0.0}));
}

TEST_CASE("minimizeLevenbergMarquardt: Rosenbrock's valley is followed to (1, 1) with Broyden updates", "[helicoid]")
{
    Rosenbrock p;
    std::vector<double> x{-1.2, 1.0};
    LevenbergMarquardtOptions o;
    o.maxIterations = 500;
    o.minGain = 0.0;
    const double cost = minimizeLevenbergMarquardt(p, x, o);
    CAPTURE(x[0], x[1], cost);
    REQUIRE(x[0] == Approx(1.0).margin(1e-4));
    REQUIRE(x[1] == Approx(1.0).margin(2e-4));
    REQUIRE(cost < 1e-8);
    // Fewer iterations than it needs: the cost still only goes down from the start's.
    std::vector<double> y{-1.2, 1.0};
    o.maxIterations = 3;
    REQUIRE(minimizeLevenbergMarquardt(p, y, o) <= residualCost(p, {-1.2, 1.0}));
}

TEST_CASE("minimizeLevenbergMarquardt: stops at once where closeEnough says so, and refuses 6 unknowns", "[helicoid]")
{
    struct Done : LinearProblem
    {
        bool closeEnough(const double*) const override { return true; }
    } p;
    std::vector<double> x{5.0, -7.0};
    minimizeLevenbergMarquardt(p, x);
    REQUIRE(p.evaluations == 1);  // the start's residuals only
    REQUIRE(x == std::vector<double>{5.0, -7.0});
    std::vector<double> six(6, 0.0), none;
    REQUIRE_THROWS_AS(minimizeLevenbergMarquardt(p, six), ValueError);
    REQUIRE_THROWS_AS(minimizeLevenbergMarquardt(p, none), ValueError);
}

TEST_CASE("minimizeNelderMead: a quadratic bowl, its boxed minimum, and non-finite values", "[helicoid]")
{
    int calls = 0;
    auto bowl = [&](const std::vector<double>& v) {
        ++calls;
        return (v[0] - 0.3) * (v[0] - 0.3) + 2.0 * (v[1] + 0.7) * (v[1] + 0.7) + 1.0;
    };
    NelderMeadOptions o;
    o.lower = {-5.0, -5.0};
    o.upper = {5.0, 5.0};
    o.initialStep = {0.5, 0.5};
    o.xtolAbs = 1e-8;
    o.ftolRel = 1e-14;
    o.maxEvaluations = 2000;
    std::vector<double> x{2.0, 2.0};
    double f = minimizeNelderMead(bowl, x, o);
    REQUIRE(x[0] == Approx(0.3).margin(1e-5));
    REQUIRE(x[1] == Approx(-0.7).margin(1e-5));
    REQUIRE(f == Approx(1.0).margin(1e-9));
    REQUIRE(calls <= o.maxEvaluations);

    // The minimum outside the box: x[1] on its bound, and a start outside moved in.
    o.lower = {-5.0, 0.0};
    x = {2.0, -3.0};
    f = minimizeNelderMead(bowl, x, o);
    REQUIRE(x[1] == Approx(0.0).margin(1e-6));
    REQUIRE(x[0] == Approx(0.3).margin(1e-5));
    REQUIRE(f == Approx(1.0 + 2.0 * 0.49).margin(1e-6));

    // NaN counts as 1e30: the search stays where f is finite.
    auto half = [](const std::vector<double>& v) { return v[0] > 1.0 ? std::numeric_limits<double>::quiet_NaN() : (v[0] - 2.0) * (v[0] - 2.0); };
    NelderMeadOptions h;
    h.lower = {-5.0};
    h.upper = {5.0};
    h.initialStep = {0.25};
    h.xtolAbs = 1e-9;
    h.ftolRel = 1e-14;
    h.maxEvaluations = 500;
    std::vector<double> z{-1.0};
    f = minimizeNelderMead(half, z, h);
    REQUIRE(z[0] <= 1.0);
    REQUIRE(z[0] == Approx(1.0).margin(1e-3));
    REQUIRE(std::isfinite(f));
}
