#include "../TestUtil.h"

#include <vdbhair/helicoid/FastMath.h>

#include <random>

using namespace vdbhair;

// The oracle is the C library: every fast form must agree with it to about 1e-15 (absolute, for
// results of size 1 or π) over the arguments tracing meets, and on the special values.

TEST_CASE("fastmath: sinCos and sinCosLane agree with std::sin and std::cos", "[helicoid][fastmath]")
{
    std::mt19937_64 gen(5);
    std::vector<double> xs = {0.0, -0.0, 1e-300, M_PI_4, M_PI_2, M_PI, -M_PI, 2 * M_PI, 1e4, -99999.5, 0.5 * M_PI * 7};
    for (double scale : {1.0, 10.0, 1000.0, 99999.0}) {
        std::uniform_real_distribution<double> u(-scale, scale);
        for (int i = 0; i < 20000; ++i) xs.push_back(u(gen));
    }
    double worst = 0.0, worstLane = 0.0;
    for (double x : xs) {
        double s, c, sl, cl;
        fastmath::sinCos(x, s, c);
        fastmath::sinCosLane(x, sl, cl);
        worst = std::max({worst, std::abs(s - std::sin(x)), std::abs(c - std::cos(x))});
        worstLane = std::max({worstLane, std::abs(sl - std::sin(x)), std::abs(cl - std::cos(x))});
    }
    CAPTURE(worst, worstLane);
    CHECK(worst < 2e-15);
    CHECK(worstLane < 2e-15);
}

TEST_CASE("fastmath: atan2 and atan2Lane agree with std::atan2 in every quadrant", "[helicoid][fastmath]")
{
    std::mt19937_64 gen(9);
    std::vector<std::pair<double, double>> args = {{0, 1}, {1, 0}, {0, -1}, {-1, 0}, {1, 1}, {-1, -1}, {1, -1}, {-1, 1},
                                                   {0, 0}, {1e-300, 1}, {1, 1e-300}, {3, 1e-17}, {0.41421356237309503, 1.0}};
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    std::uniform_real_distribution<double> e(-8.0, 8.0);
    for (int i = 0; i < 50000; ++i) args.emplace_back(u(gen) * std::pow(10.0, e(gen)), u(gen) * std::pow(10.0, e(gen)));
    double worst = 0.0, worstLane = 0.0;
    for (const auto& [y, x] : args) {
        const double want = std::atan2(y, x);
        worst = std::max(worst, std::abs(fastmath::atan2(y, x) - want));
        worstLane = std::max(worstLane, std::abs(fastmath::atan2Lane(y, x) - want));
    }
    CAPTURE(worst, worstLane);
    CHECK(worst < 2e-15);
    CHECK(worstLane < 2e-15);
}

TEST_CASE("fastmath: roundLane rounds to the nearest integer", "[helicoid][fastmath]")
{
    for (double x : {0.0, 0.4, 0.6, -0.4, -0.6, 2.5, 3.5, -2.5, 1e6 + 0.3, -123456789.7}) {
        CAPTURE(x);
        CHECK(std::abs(fastmath::roundLane(x) - x) <= 0.5);
        CHECK(fastmath::roundLane(x) == std::nearbyint(x));  // halves to even, as the default rounding mode
    }
}
