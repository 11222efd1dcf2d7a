/// @file Quantile.h
/// @brief The library's order statistics: the k-th smallest value, the medians and the quantiles
/// it takes of a sample. They differ on purpose (each report keeps the rule it was defined by):
///
/// | function                 | value (sorted ascending v[0..n-1])                | NumPy method    |
/// |--------------------------|---------------------------------------------------|-----------------|
/// | orderStatistic(v, k)     | v[k]                                              |                 |
/// | upperMedian(v)           | v[n / 2] (the upper of the two middle values)     | "higher" at 0.5 |
/// | median(v)                | v[n / 2], or (v[n / 2] + v[n / 2 - 1]) / 2, n even | at 0.5          |
/// | quantile(v, q)           | linear between v[floor(q (n-1))] and the next     | "linear"        |
/// | lowerQuantile(v, q)      | v[floor(q (n-1))]                                 | "lower"         |
/// | nearestRankQuantile(v, q)| v[ceil(q n) - 1] (v[0] at q = 0)                  | "inverted_cdf"  |
///
/// Each takes the sample by value and reorders its copy (std::nth_element: linear time); pass
/// a vector that is no longer needed with std::move. An empty sample gives 0. Values must not be
/// NaN (they have no order).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <utility>
#include <vector>

namespace vdbhair {

/// @brief The @a k-th smallest of @a values (0-based; k past the end: the largest); 0 when empty.
template<class T>
T orderStatistic(std::vector<T> values, std::size_t k)
{
    if (values.empty()) return T(0);
    k = std::min(k, values.size() - 1);
    std::nth_element(values.begin(), values.begin() + std::ptrdiff_t(k), values.end());
    return values[k];
}

/// @brief The upper median of @a values: the middle value, or of two the greater (v[n / 2]); always
/// a member of the sample. 0 when empty.
template<class T>
T upperMedian(std::vector<T> values)
{
    const std::size_t mid = values.size() / 2;
    return orderStatistic(std::move(values), mid);
}

/// @brief The median of @a values: the middle value, or the mean of the two middle values, taken
/// as 0.5 * (upper + lower) (quantile(v, 0.5) is lower + 0.5 * (upper - lower), which can differ
/// in the last bit). 0 when empty.
template<class T>
T median(std::vector<T> values)
{
    if (values.empty()) return T(0);
    const std::size_t mid = values.size() / 2;
    std::nth_element(values.begin(), values.begin() + std::ptrdiff_t(mid), values.end());
    T m = values[mid];
    if (values.size() % 2 == 0) m = T(0.5) * (m + *std::max_element(values.begin(), values.begin() + std::ptrdiff_t(mid)));
    return m;
}

/// @brief The @a q quantile (0 <= q <= 1) of @a values, linear between the two nearest order
/// statistics (NumPy's default, `numpy.quantile(..., method="linear")`); 0 when empty.
inline double quantile(std::vector<double> values, double q)
{
    if (values.empty()) return 0.0;
    const double pos = std::clamp(q, 0.0, 1.0) * double(values.size() - 1);
    const std::size_t lo = std::size_t(std::floor(pos));
    std::nth_element(values.begin(), values.begin() + std::ptrdiff_t(lo), values.end());
    const double a = values[lo];
    if (lo + 1 >= values.size()) return a;
    const double b = *std::min_element(values.begin() + std::ptrdiff_t(lo) + 1, values.end());
    return a + (pos - double(lo)) * (b - a);
}

/// @brief The @a q quantile (0 <= q <= 1) of @a values rounded down to a member: the order
/// statistic floor(q (n - 1)) (`numpy.quantile(..., method="lower")`); 0 when empty.
template<class T>
T lowerQuantile(std::vector<T> values, double q)
{
    const std::size_t n = values.size();
    return n ? orderStatistic(std::move(values), std::size_t(std::clamp(q, 0.0, 1.0) * double(n - 1))) : T(0);
}

/// @brief The @a q quantile (0 <= q <= 1) of @a values by nearest rank: the least value with at
/// least a share @a q of the sample at or below it, the order statistic ceil(q n) - 1 (the first at
/// q = 0; `numpy.quantile(..., method="inverted_cdf")`); 0 when empty.
template<class T>
T nearestRankQuantile(std::vector<T> values, double q)
{
    const std::size_t n = values.size();
    if (n == 0) return T(0);
    q = std::clamp(q, 0.0, 1.0);
    const std::size_t k = std::min(n - 1, std::size_t(std::ceil(q * double(n))) - (q > 0.0 ? 1 : 0));
    return orderStatistic(std::move(values), k);
}

} // namespace vdbhair
