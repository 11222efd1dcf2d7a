#include "Frechet.h"

#include <algorithm>
#include <limits>
#include <vector>

namespace vdbhair {

double discreteFrechet(const Vec3d* a, std::size_t p, const Vec3d* b, std::size_t q)
{
    if (p == 0 || q == 0) return 0.0;
    // Row by row: F(i, j) = max(d(i, j), min(F(i-1, j), F(i, j-1), F(i-1, j-1))).
    std::vector<double> prev(q), cur(q);
    for (std::size_t i = 0; i < p; ++i) {
        for (std::size_t j = 0; j < q; ++j) {
            const double d = (a[i] - b[j]).length();
            double best;
            if (i == 0 && j == 0) best = 0.0;
            else if (i == 0) best = cur[j - 1];
            else if (j == 0) best = prev[j];
            else best = std::min({prev[j], cur[j - 1], prev[j - 1]});
            cur[j] = std::max(d, best);
        }
        std::swap(prev, cur);
    }
    return prev[q - 1];
}

double frechetCoupling(const Vec3d* a, std::size_t p, const Vec3d* b, std::size_t q, std::size_t* steps)
{
    if (p == 0 || q == 0) {
        if (steps) *steps = 0;
        return 0.0;
    }
    // C(i, j) = d(i, j) + min(C(i-1, j), C(i, j-1), C(i-1, j-1)); ties keep the shorter coupling.
    std::vector<double> prev(q), cur(q);
    std::vector<std::size_t> prevN(q), curN(q);
    for (std::size_t i = 0; i < p; ++i) {
        for (std::size_t j = 0; j < q; ++j) {
            const double d = (a[i] - b[j]).length();
            if (i == 0 && j == 0) {
                cur[j] = d;
                curN[j] = 1;
                continue;
            }
            double best = std::numeric_limits<double>::max();
            std::size_t n = 0;
            auto consider = [&](double c, std::size_t k) {
                if (c < best || (c == best && k < n)) { best = c; n = k; }
            };
            if (i > 0 && j > 0) consider(prev[j - 1], prevN[j - 1]);
            if (i > 0) consider(prev[j], prevN[j]);
            if (j > 0) consider(cur[j - 1], curN[j - 1]);
            cur[j] = d + best;
            curN[j] = n + 1;
        }
        std::swap(prev, cur);
        std::swap(prevN, curN);
    }
    if (steps) *steps = prevN[q - 1];
    return prev[q - 1];
}

} // namespace vdbhair
