#include "FeatureMap.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/Parallel.h>
#include <vdbhair/Quantile.h>
#include <vdbhair/strands/PointCloud.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

namespace vdbhair {

void UvGrid::pixelOf(double u, double v, int& x, int& y) const
{
    x = std::clamp(int(std::lround((u - u0) / spacing)), 0, width - 1);
    y = std::clamp(int(std::lround((v - v0) / spacing)), 0, height - 1);
}

UvGrid uvGridAround(const std::vector<Vec3d>& scalpCoords, double spacing, int padPixels)
{
    if (!(spacing > 0.0) || !std::isfinite(spacing))
        throw ValueError("feature map: spacing " + std::to_string(spacing) + ": a positive finite (u, v) step");
    if (scalpCoords.empty()) throw ValueError("feature map: no roots to cover");
    double umin = M_PI, umax = 0.0, vmin = M_PI, vmax = 0.0;
    for (const Vec3d& s : scalpCoords) {
        umin = std::min(umin, s.x()); umax = std::max(umax, s.x());
        vmin = std::min(vmin, s.y()); vmax = std::max(vmax, s.y());
    }
    const double pad = padPixels * spacing, eps = 1e-6;
    umin = std::max(eps, umin - pad); vmin = std::max(eps, vmin - pad);
    umax = std::min(M_PI - eps, umax + pad); vmax = std::min(M_PI - eps, vmax + pad);
    UvGrid g;
    g.spacing = spacing;
    g.u0 = umin;
    g.v0 = vmin;
    const double w = std::floor((umax - umin) / spacing) + 1, h = std::floor((vmax - vmin) / spacing) + 1;
    if (w > 4096 || h > 4096)
        throw LimitError("feature map: " + std::to_string(long(w)) + " x " + std::to_string(long(h)) +
                         " pixels at spacing " + std::to_string(spacing) + " exceed 4096 x 4096");
    g.width = int(w);
    g.height = int(h);
    return g;
}

namespace {
std::vector<Vec3d> flatten(const std::vector<Vec3d>& coords)
{
    std::vector<Vec3d> out(coords.size());
    for (std::size_t i = 0; i < coords.size(); ++i) out[i] = Vec3d(coords[i].x(), coords[i].y(), 0.0);
    return out;
}
} // namespace

std::vector<double> nearestUvDistances(const std::vector<Vec3d>& scalpCoords, bool threaded)
{
    std::vector<double> nn(scalpCoords.size(), 0.0);
    if (scalpCoords.size() < 2) return nn;
    const std::vector<Vec3d> pts = flatten(scalpCoords);
    PointCloud cloud{&pts};
    PointKdTree tree(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(16));
    tree.buildIndex();
    forEachIndex(pts.size(), threaded, [&](std::size_t i) {
        std::uint32_t idx[2];
        double d2[2];
        const double q[3] = {pts[i].x(), pts[i].y(), 0.0};
        if (tree.knnSearch(q, 2, idx, d2) == 2) nn[i] = std::sqrt(d2[1]);
    }, 512);
    return nn;
}

double medianUvSpacing(const std::vector<Vec3d>& scalpCoords)
{
    if (scalpCoords.size() < 2) return 0.0;
    return upperMedian(nearestUvDistances(scalpCoords, false));
}

FeatureImage buildFeatureMap(const UvGrid& grid, const std::vector<Vec3d>& rootCoords, const float* features,
                             int channels, const std::vector<Vec3d>& maskCoords, double maskRadius)
{
    if (rootCoords.empty()) throw ValueError("feature map: no roots to interpolate from");
    FeatureImage map(grid.width, grid.height, channels);
    const std::vector<Vec3d> roots = flatten(rootCoords);
    PointCloud rootCloud{&roots};
    PointKdTree rootTree(3, rootCloud, nanoflann::KDTreeSingleIndexAdaptorParams(16));
    rootTree.buildIndex();
    const std::size_t k = std::min<std::size_t>(4, roots.size());
    for (int y = 0; y < grid.height; ++y) {
        for (int x = 0; x < grid.width; ++x) {
            const double q[3] = {grid.u(x), grid.v(y), 0.0};
            std::uint32_t idx[4];
            double d2[4];
            const std::size_t got = rootTree.knnSearch(q, k, idx, d2);
            float* px = map.pixel(x, y);
            if (d2[0] < 1e-24) {
                std::copy(features + std::size_t(idx[0]) * channels, features + std::size_t(idx[0] + 1) * channels, px);
            } else {
                double wsum = 0.0;
                std::vector<double> acc(std::size_t(channels), 0.0);
                for (std::size_t j = 0; j < got; ++j) {
                    const double w = 1.0 / d2[j];
                    wsum += w;
                    const float* f = features + std::size_t(idx[j]) * channels;
                    for (int c = 0; c < channels; ++c) acc[std::size_t(c)] += w * f[c];
                }
                for (int c = 0; c < channels; ++c) px[c] = float(acc[std::size_t(c)] / wsum);
            }
        }
    }
    map.valid = uvMask(grid, maskCoords, maskRadius);
    return map;
}

std::vector<std::uint8_t> uvMask(const UvGrid& grid, const std::vector<Vec3d>& coords, double radius)
{
    std::vector<std::uint8_t> valid(std::size_t(grid.width) * std::size_t(grid.height), 0);
    if (coords.empty()) return valid;
    const std::vector<Vec3d> pts = flatten(coords);
    PointCloud cloud{&pts};
    PointKdTree tree(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(16));
    tree.buildIndex();
    for (int y = 0; y < grid.height; ++y)
        for (int x = 0; x < grid.width; ++x) {
            const double q[3] = {grid.u(x), grid.v(y), 0.0};
            std::uint32_t i;
            double d2;
            tree.knnSearch(q, 1, &i, &d2);
            valid[std::size_t(y) * grid.width + x] = d2 <= radius * radius ? 1 : 0;
        }
    return valid;
}

bool nearestFeature(const FeatureImage& map, const UvGrid& grid, double u, double v, float* out)
{
    int x, y;
    grid.pixelOf(u, v, x, y);
    if (map.isValid(x, y)) {
        std::copy(map.pixel(x, y), map.pixel(x, y) + map.channels, out);
        return true;
    }
    // Search outward ring by ring for the nearest valid pixel.
    const int rings = std::max(map.width, map.height);
    for (int r = 1; r < rings; ++r) {
        double best = std::numeric_limits<double>::max();
        int bx = -1, by = -1;
        for (int j = y - r; j <= y + r; ++j) {
            for (int i = x - r; i <= x + r; ++i) {
                if (std::max(std::abs(i - x), std::abs(j - y)) != r) continue;
                if (i < 0 || j < 0 || i >= map.width || j >= map.height || !map.isValid(i, j)) continue;
                const double d = double(i - x) * (i - x) + double(j - y) * (j - y);
                if (d < best) { best = d; bx = i; by = j; }
            }
        }
        if (bx >= 0) {
            std::copy(map.pixel(bx, by), map.pixel(bx, by) + map.channels, out);
            return true;
        }
    }
    return false;
}

} // namespace vdbhair
