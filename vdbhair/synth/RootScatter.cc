#include "RootScatter.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/Random.h>
#include <vdbhair/strands/PointCloud.h>
#include <vdbhair/strands/Measures.h>

#include <vdbhair/Parallel.h>

#include <algorithm>
#include <cmath>
#include <string>

namespace vdbhair {

namespace {
std::vector<double> pixelAreas(const ScalpMap& map, const UvGrid& grid, const FeatureImage& mask)
{
    std::vector<double> area(mask.pixelCount(), 0.0);
    const double h = grid.spacing * 0.5;
    for (int y = 0; y < grid.height; ++y)
        for (int x = 0; x < grid.width; ++x) {
            if (!mask.isValid(x, y)) continue;
            const double u = grid.u(x), v = grid.v(y);
            const Vec3d du = (map.toWorld(Vec3d(u + h, v, 0)) - map.toWorld(Vec3d(u - h, v, 0))) / (2 * h);
            const Vec3d dv = (map.toWorld(Vec3d(u, v + h, 0)) - map.toWorld(Vec3d(u, v - h, 0))) / (2 * h);
            area[std::size_t(y) * grid.width + x] = du.cross(dv).length() * grid.spacing * grid.spacing;
        }
    return area;
}
} // namespace

double regionArea(const ScalpMap& map, const UvGrid& grid, const FeatureImage& mask)
{
    double a = 0.0;
    for (double v : pixelAreas(map, grid, mask)) a += v;
    return a;
}

ScatteredRoots scatterRoots(const ScalpMap& map, const UvGrid& grid, const FeatureImage& mask,
                            const RootScatterParams& params, bool threaded)
{
    if (params.count == 0) throw ValueError("scatterRoots: a count of 0 roots");
    // 1. Pixel areas and their running sum.
    const std::vector<double> area = pixelAreas(map, grid, mask);
    std::vector<double> cdf(area.size());
    double total = 0.0;
    for (std::size_t i = 0; i < area.size(); ++i) cdf[i] = (total += area[i]);
    if (!(total > 0.0)) throw LookupError("scatterRoots: the scalp region holds no valid pixel");
    ScatteredRoots out;
    out.area = total;
    const std::size_t n = params.count;
    out.positions.resize(n);
    out.scalp.resize(n);
    const auto forEach = [&](auto&& fn) { forEachIndex(n, threaded, fn, 512); };
    // 2. Random roots, area-weighted.
    forEach([&](std::size_t i) {
        Rng rng(params.seed, 0x700754u + params.stream, i);
        const double t = rng.uniform() * total;
        const std::size_t p = std::size_t(std::upper_bound(cdf.begin(), cdf.end(), t) - cdf.begin());
        const std::size_t pix = std::min(p, cdf.size() - 1);
        const int x = int(pix % std::size_t(grid.width)), y = int(pix / std::size_t(grid.width));
        const double u = grid.u(x + rng.uniform() - 0.5), v = grid.v(y + rng.uniform() - 0.5);
        out.scalp[i] = Vec3d(u, v, 0.0);
        out.positions[i] = map.toWorld(out.scalp[i]);
    });
    // 3. Relaxation (Turk 2001), Jacobi, on the roots in spatial order: neighbours then sit near
    // each other in memory and the k-d tree searches stay in cache (0.9 s → 0.52 s for 100,000 roots).
    // Each root's push sums its neighbours by distance, so the order changes no result.
    const std::vector<std::uint32_t> order = spatialOrder(out.positions);
    std::vector<Vec3d> pos(n), sc(n);
    for (std::size_t i = 0; i < n; ++i) {
        pos[i] = out.positions[order[i]];
        sc[i] = out.scalp[order[i]];
    }
    const double d = std::sqrt(2.0 * total / (std::sqrt(3.0) * double(n))), r = 2.0 * d;
    std::vector<Vec3d> next(n), nextScalp(n);
    for (int it = 0; it < params.iterations && n > 1; ++it) {
        PointCloud cloud{&pos};
        PointKdTree tree(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(16));
        tree.buildIndex();
        forEach([&](std::size_t i) {
            constexpr std::size_t K = 7;
            std::uint32_t idx[K];
            double d2[K];
            const Vec3d& p = pos[i];
            const double q[3] = {p.x(), p.y(), p.z()};
            const std::size_t got = tree.knnSearch(q, std::min(K, n), idx, d2);
            Vec3d push(0.0);
            for (std::size_t j = 0; j < got; ++j) {
                if (idx[j] == i) continue;
                const double dist = std::sqrt(d2[j]);
                if (dist >= r || dist <= 0.0) continue;
                push += (p - pos[idx[j]]) / dist * ((r - dist) / r * 0.25 * d);
            }
            const double len = push.length();
            if (len > 0.5 * d) push *= 0.5 * d / len;
            Vec3d s = map.toScalp(p + push);
            s.z() = 0.0;
            int x, y;
            grid.pixelOf(s.x(), s.y(), x, y);
            const bool inside = s.x() > grid.u(-0.5) && s.x() < grid.u(grid.width - 0.5) && s.y() > grid.v(-0.5) &&
                                s.y() < grid.v(grid.height - 0.5) && mask.isValid(x, y);
            next[i] = inside ? map.toWorld(s) : p;
            nextScalp[i] = inside ? s : sc[i];
        });
        pos.swap(next);
        sc.swap(nextScalp);
    }
    for (std::size_t i = 0; i < n; ++i) {
        out.positions[order[i]] = pos[i];
        out.scalp[order[i]] = sc[i];
    }
    return out;
}

} // namespace vdbhair
