/// @file Quantile.h
/// @brief The library's one quantile: the q-th quantile of a sample, linear between the two
/// nearest order statistics (NumPy's default, `numpy.quantile(..., method="linear")`).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

namespace vdbhair {

/// @brief The @a q quantile (0 <= q <= 1) of @a values (taken by value: reordered); 0 when empty.
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

} // namespace vdbhair
