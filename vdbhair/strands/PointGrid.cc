#include "PointGrid.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/Memory.h>
#include <vdbhair/Parallel.h>

#include <algorithm>
#include <string>

namespace vdbhair {

PointGrid::PointGrid(const std::vector<Vec3f>& points, bool threaded)
{
    const std::size_t n = points.size();
    if (n > (std::size_t(1) << 31)) throw ValueError("point grid: " + std::to_string(n) + " points: at most 2^31");
    if (n == 0) return;
    // The bounding box, a box a range of points, combined (min and max: in any order).
    const std::size_t ranges = std::min<std::size_t>(64, (n + 65535) / 65536);
    std::vector<BBox> boxes(ranges);
    forEachIndex(ranges, threaded, [&](std::size_t r) {
        for (std::size_t i = n * r / ranges; i < n * (r + 1) / ranges; ++i) boxes[r].expand(points[i]);
    }, 1);
    BBox box;
    for (const BBox& b : boxes) {
        box.expand(b.min);
        box.expand(b.max);
    }
    const Vec3d lo(box.min.x(), box.min.y(), box.min.z()), extent = Vec3d(box.max.x(), box.max.y(), box.max.z()) - lo;
    const double longest = std::max({extent.x(), extent.y(), extent.z()});
    mOrigin = lo;
    // About one cell a point over the box (a flat or thin box counted as a thousandth of its longest
    // side across), then coarser until there are at most 2n + 64 cells.
    if (longest > 0.0) {
        const double floor = longest * 1e-3;
        const double volume = std::max(extent.x(), floor) * std::max(extent.y(), floor) * std::max(extent.z(), floor);
        mCell = std::cbrt(volume / double(n));
    }
    for (;;) {
        std::size_t cells = 1;
        for (int a = 0; a < 3; ++a) {
            mDims[a] = int(std::min(std::floor(extent[a] / mCell), double(1 << 30))) + 1;
            cells *= std::size_t(mDims[a]);
        }
        if (cells <= 2 * n + 64) break;
        mCell *= 1.25;
    }
    const std::size_t cells = std::size_t(mDims[0]) * std::size_t(mDims[1]) * std::size_t(mDims[2]);
    // The large arrays ask for huge pages: a fresh page costs a fault (Memory.h).
    std::vector<std::uint32_t> key;
    reserveHugePages(key, n);
    key.resize(n);
    forEachIndex(n, threaded, [&](std::size_t i) {
        std::size_t c[3];
        for (int a = 0; a < 3; ++a) c[a] = std::min(std::size_t((double(points[i][a]) - mOrigin[a]) / mCell), std::size_t(mDims[a] - 1));
        key[i] = std::uint32_t(c[0] + std::size_t(mDims[0]) * (c[1] + std::size_t(mDims[1]) * c[2]));
    }, 4096);
    // A counting sort, stable: within a cell, points keep their order.
    reserveHugePages(mStart, cells + 1);
    mStart.assign(cells + 1, 0);
    for (const std::uint32_t k : key) ++mStart[k + 1];
    for (std::size_t c = 0; c < cells; ++c) mStart[c + 1] += mStart[c];
    reserveHugePages(mPoints, n);
    reserveHugePages(mIndex, n);
    mPoints.resize(n);
    mIndex.resize(n);
    std::vector<std::uint32_t> next(mStart.begin(), mStart.end() - 1);
    for (std::size_t i = 0; i < n; ++i) {
        const std::uint32_t at = next[key[i]]++;
        mPoints[at] = points[i];
        mIndex[at] = std::uint32_t(i);
    }
    for (int a = 0; a < 3; ++a) mBlockDims[a] = (mDims[a] + kBlock - 1) / kBlock;
    mBlock.assign(std::size_t(mBlockDims[0]) * std::size_t(mBlockDims[1]) * std::size_t(mBlockDims[2]), 0);
    std::size_t c = 0;
    for (int z = 0; z < mDims[2]; ++z) {
        for (int y = 0; y < mDims[1]; ++y) {
            for (int x = 0; x < mDims[0]; ++x, ++c) {
                if (mStart[c + 1] == mStart[c]) continue;
                mBlock[std::size_t(x / kBlock) + std::size_t(mBlockDims[0]) * (std::size_t(y / kBlock) + std::size_t(mBlockDims[1]) * std::size_t(z / kBlock))] = 1;
            }
        }
    }
}

std::uint32_t PointGrid::nearest(const Vec3d& p, double& d2) const
{
    if (mIndex.empty()) return ~0u;
    std::uint32_t best = ~0u;
    double bestD2 = std::numeric_limits<double>::infinity();
    auto closer = [&](std::uint32_t index, double e2) {
        if (e2 < bestD2 || (e2 == bestD2 && index < best)) {
            bestD2 = e2;
            best = index;
        }
        return true;
    };
    // Every point within r is found: when the best lies within r it is the nearest. Out from a
    // quarter cell (or the bound, when nearer), twice as far each time, and never past the bound (the
    // bound's point lies within it) or past the best found.
    const double limit = std::isfinite(d2) && d2 >= 0.0 ? std::sqrt(d2) * (1.0 + 1e-9) + 1e-300 : std::numeric_limits<double>::infinity();
    const double diagonal = mCell * std::sqrt(double(mDims[0]) * mDims[0] + double(mDims[1]) * mDims[1] + double(mDims[2]) * mDims[2]);
    const double farthest = 2.0 * diagonal + (p - mOrigin).length();  // every point lies within it
    double r = std::min(limit, 0.25 * mCell);  // at most 2^3 cells
    for (;;) {
        forEachWithin(p, r, closer);
        if (best != ~0u && bestD2 <= r * r) break;
        if (r >= farthest) break;
        r = best != ~0u ? std::sqrt(bestD2) * (1.0 + 1e-9) + 1e-300 : std::min(2.0 * r, r >= limit ? farthest : limit);
    }
    d2 = bestD2;
    return best;
}

} // namespace vdbhair
