#include "RootSubsample.h"

#include <vdbhair/Parallel.h>
#include <vdbhair/strands/PointCloud.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace vdbhair {

namespace {

/// The largest value and its index (the lower index on ties): an associative, commutative
/// reduction, so the result does not depend on how the range is split.
struct Farthest
{
    double d2 = -1.0;
    std::size_t index = 0;
    void take(double v, std::size_t i)
    {
        if (v > d2 || (v == d2 && i < index)) {
            d2 = v;
            index = i;
        }
    }
};

} // namespace

RootSelection selectEvenRoots(const StrandSet& strands, std::size_t count, bool threaded)
{
    RootSelection sel;
    const std::size_t n = strands.numStrands();
    if (n == 0 || count == 0) return sel;
    std::vector<Vec3d> roots(n);
    for (std::size_t i = 0; i < n; ++i) {
        const Vec3f& r = strands.root(i);
        roots[i] = Vec3d(r.x(), r.y(), r.z());
    }
    const std::size_t k = std::min(count, n);

    // The first root: the one nearest the centroid.
    Vec3d c(0.0);
    for (const Vec3d& r : roots) c += r;
    c /= double(n);
    std::size_t first = 0;
    for (std::size_t i = 1; i < n; ++i) {
        if ((roots[i] - c).lengthSqr() < (roots[first] - c).lengthSqr()) first = i;
    }

    // Farthest-point sampling: minD2[i] is root i's squared distance to the nearest taken root.
    std::vector<double> minD2(n, std::numeric_limits<double>::infinity());
    std::vector<char> taken(n, 0);
    std::size_t last = first;
    taken[first] = 1;
    sel.strands.reserve(k);
    sel.strands.push_back(std::uint32_t(first));
    for (std::size_t step = 1; step <= k; ++step) {
        const Vec3d p = roots[last];
        auto body = [&](const tbb::blocked_range<std::size_t>& r, Farthest f) {
            for (std::size_t i = r.begin(); i != r.end(); ++i) {
                minD2[i] = std::min(minD2[i], (roots[i] - p).lengthSqr());
                if (!taken[i]) f.take(minD2[i], i);
            }
            return f;
        };
        auto join = [](Farthest a, const Farthest& b) {
            a.take(b.d2, b.index);
            return a;
        };
        const tbb::blocked_range<std::size_t> all(0, n, 4096);
        const Farthest f = threaded ? tbb::parallel_reduce(all, Farthest{}, body, join) : body(all, Farthest{});
        if (step == k) {
            // Every root is now within the coverage radius of a taken one (taken roots at 0).
            double cover = 0.0;
            for (std::size_t i = 0; i < n; ++i) cover = std::max(cover, minD2[i]);
            sel.coverageRadius = std::sqrt(cover);
            break;
        }
        last = f.index;
        taken[last] = 1;
        sel.strands.push_back(std::uint32_t(last));
    }
    std::sort(sel.strands.begin(), sel.strands.end());

    // The smallest spacing between taken roots (each one's nearest other taken root).
    if (k >= 2) {
        std::vector<Vec3d> pts(k);
        for (std::size_t j = 0; j < k; ++j) pts[j] = roots[sel.strands[j]];
        const PointCloud cloud{&pts};
        PointKdTree tree(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(10));
        tree.buildIndex();
        std::vector<double> nearest(k);
        forEachIndex(k, threaded, [&](std::size_t j) {
            const double q[3] = {pts[j].x(), pts[j].y(), pts[j].z()};
            std::uint32_t idx[2] = {0, 0};
            double d2[2] = {0.0, 0.0};
            tree.knnSearch(q, 2, idx, d2);
            nearest[j] = d2[1];
        }, 256);
        sel.minSpacing = std::sqrt(*std::min_element(nearest.begin(), nearest.end()));
    }
    return sel;
}

StrandSet subsampleStrands(const StrandSet& strands, std::size_t count, RootSelection* selection, bool threaded)
{
    RootSelection sel = selectEvenRoots(strands, count, threaded);
    std::vector<char> keep(strands.numStrands(), 0);
    for (std::uint32_t i : sel.strands) keep[i] = 1;
    StrandSet out = selectStrands(strands, keep);
    if (selection) *selection = std::move(sel);
    return out;
}

} // namespace vdbhair
