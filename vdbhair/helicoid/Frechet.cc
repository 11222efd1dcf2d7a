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

bool discreteFrechetWithin(const Vec3d* a, std::size_t p, const Vec3d* b, std::size_t q, double eps)
{
    if (p == 0 || q == 0) return true;
    // The same distances as discreteFrechet (not squared: the answer must agree at eps = d).
    auto free = [&](std::size_t i, std::size_t j) { return (a[i] - b[j]).length() <= eps; };
    // Reachable cells of the previous row lie in [first, last] (flags inside); a cell is reachable
    // if free and its left, lower or lower-left neighbour is.
    std::vector<char> prev(q, 0), cur(q, 0);
    std::size_t first = 0, last = 0;
    if (!free(0, 0)) return false;
    prev[0] = 1;
    while (last + 1 < q && free(0, last + 1)) prev[++last] = 1;
    for (std::size_t i = 1; i < p; ++i) {
        std::size_t newFirst = q, newLast = 0;
        bool left = false;
        for (std::size_t j = first; j < q; ++j) {
            const bool below = j <= last && prev[j];
            const bool diag = j > first && j - 1 <= last && prev[j - 1];
            if (!below && !diag && !left) {
                cur[j] = 0;
                if (j > last) break;  // nothing further right can be reached
                continue;
            }
            left = free(i, j);
            cur[j] = left;
            if (left) {
                newFirst = std::min(newFirst, j);
                newLast = j;
            }
        }
        if (newFirst == q) return false;
        std::swap(prev, cur);
        first = newFirst;
        last = newLast;
    }
    return last == q - 1 && prev[q - 1];
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
