#include "Frechet.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace vdbhair {

double discreteFrechet(const Vec3d* a, std::size_t p, const Vec3d* b, std::size_t q)
{
    if (p == 0 || q == 0) return 0.0;
    auto dist2 = [&](std::size_t i, std::size_t j) {
        const double x = a[i].x() - b[j].x(), y = a[i].y() - b[j].y(), z = a[i].z() - b[j].z();
        return x * x + y * y + z * z;
    };
    // An upper bound: the largest distance along one monotone coupling, the staircase closest to
    // the diagonal. No cell farther apart than that can be on an optimal coupling, so the
    // recurrence below visits only the band of cells within it (a few per row for close curves)
    // and still gives the exact distance.
    double bound = 0.0;
    for (std::size_t i = 0, j = 0;;) {
        bound = std::max(bound, dist2(i, j));
        if (i + 1 == p && j + 1 == q) break;
        // Step to the neighbour that stays closest to the diagonal i / (p - 1) = j / (q - 1).
        if (i + 1 == p) ++j;
        else if (j + 1 == q) ++i;
        else {
            const double di = double(i + 1) * double(q - 1), dj = double(j + 1) * double(p - 1);
            if (di < dj) ++i;
            else if (dj < di) ++j;
            else { ++i; ++j; }
        }
    }
    // Row by row: F(i, j) = max(d(i, j), min(F(i-1, j), F(i, j-1), F(i-1, j-1))), on squared
    // distances (max and min commute with the square root, so the result is the same length),
    // over the cells within the bound: those of the previous row lie in [first, last].
    constexpr double inf = std::numeric_limits<double>::infinity();
    std::vector<double> prev(q, inf), cur(q, inf);
    std::size_t first = 0, last = 0;
    prev[0] = dist2(0, 0);
    for (std::size_t j = 1; j < q; ++j) {
        const double d = dist2(0, j);
        if (d > bound) break;
        prev[j] = std::max(d, prev[j - 1]);
        last = j;
    }
    for (std::size_t i = 1; i < p; ++i) {
        std::size_t newFirst = q, newLast = 0;
        double left = inf;
        for (std::size_t j = first; j < q; ++j) {
            const double below = j <= last ? prev[j] : inf;
            const double diag = j > first && j - 1 <= last ? prev[j - 1] : inf;
            const double best = std::min(std::min(below, diag), left);
            if (best == inf && j > last) break;  // nothing further right is within the bound
            const double d = dist2(i, j);
            left = (best == inf || d > bound) ? inf : std::max(d, best);
            cur[j] = left;
            if (left != inf) {
                newFirst = std::min(newFirst, j);
                newLast = j;
            }
        }
        // Clear the previous row's band before it becomes the next row's output.
        for (std::size_t j = first; j <= last; ++j) prev[j] = inf;
        std::swap(prev, cur);
        first = newFirst;
        last = newLast;
        if (first == q) return std::sqrt(bound);  // unreachable: rounding; the bound is a coupling's value
    }
    return std::sqrt(prev[q - 1] == inf ? bound : prev[q - 1]);
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
    // C(i, j) = d(i, j) + min(C(i-1, j-1), C(i-1, j), C(i, j-1)); ties keep the shorter
    // coupling (in that order of preference when the lengths tie too). Each row's distances are
    // computed first, in a loop the compiler vectorizes.
    std::vector<double> prev(q), cur(q), d(q);
    std::vector<std::size_t> prevN(q), curN(q);
    auto row = [&](const Vec3d& ai) {
        for (std::size_t j = 0; j < q; ++j) {
            const double x = ai.x() - b[j].x(), y = ai.y() - b[j].y(), z = ai.z() - b[j].z();
            d[j] = std::sqrt(x * x + y * y + z * z);
        }
    };
    row(a[0]);
    prev[0] = d[0];
    prevN[0] = 1;
    for (std::size_t j = 1; j < q; ++j) {
        prev[j] = prev[j - 1] + d[j];
        prevN[j] = j + 1;
    }
    for (std::size_t i = 1; i < p; ++i) {
        row(a[i]);
        cur[0] = prev[0] + d[0];
        curN[0] = i + 1;
        for (std::size_t j = 1; j < q; ++j) {
            double best = prev[j - 1];
            std::size_t n = prevN[j - 1];
            if (prev[j] < best || (prev[j] == best && prevN[j] < n)) { best = prev[j]; n = prevN[j]; }
            if (cur[j - 1] < best || (cur[j - 1] == best && curN[j - 1] < n)) { best = cur[j - 1]; n = curN[j - 1]; }
            cur[j] = d[j] + best;
            curN[j] = n + 1;
        }
        std::swap(prev, cur);
        std::swap(prevN, curN);
    }
    if (steps) *steps = prevN[q - 1];
    return prev[q - 1];
}

void densifyPolyline(const std::vector<Vec3d>& pts, std::size_t a, std::size_t b, double spacing, std::vector<Vec3d>& out)
{
    out.clear();
    out.push_back(pts[a]);
    for (std::size_t i = a; i < b; ++i) {
        const Vec3d d = pts[i + 1] - pts[i];
        const int n = std::max(1, int(std::ceil(d.length() / spacing - 1e-9)));
        for (int k = 1; k <= n; ++k) out.push_back(pts[i] + d * (double(k) / n));
    }
}

} // namespace vdbhair
