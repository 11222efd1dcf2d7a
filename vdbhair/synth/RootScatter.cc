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

/// Step 3, Turk's relaxation (Jacobi), on the roots in spatial order: neighbours then sit near
/// each other in memory and the k-d tree searches stay in cache (0.9 s → 0.52 s for 100,000 roots).
/// Each root's push sums its neighbours by distance, so the order changes no result. A root's
/// spacing d is @a spacingAt its (u, v).
template <typename SpacingAt>
void relaxRoots(const ScalpMap& map, const UvGrid& grid, const FeatureImage& mask, int iterations, bool threaded,
                const SpacingAt& spacingAt, ScatteredRoots& out)
{
    const std::size_t n = out.positions.size();
    const std::vector<std::uint32_t> order = spatialOrder(out.positions);
    std::vector<Vec3d> pos(n), sc(n);
    for (std::size_t i = 0; i < n; ++i) {
        pos[i] = out.positions[order[i]];
        sc[i] = out.scalp[order[i]];
    }
    std::vector<Vec3d> next(n), nextScalp(n);
    for (int it = 0; it < iterations && n > 1; ++it) {
        PointCloud cloud{&pos};
        PointKdTree tree(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(16));
        tree.buildIndex();
        forEachIndex(n, threaded, [&](std::size_t i) {
            constexpr std::size_t K = 7;
            std::uint32_t idx[K];
            double d2[K];
            const Vec3d& p = pos[i];
            const double d = spacingAt(sc[i]), r = 2.0 * d;
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
        }, 512);
        pos.swap(next);
        sc.swap(nextScalp);
    }
    for (std::size_t i = 0; i < n; ++i) {
        out.positions[order[i]] = pos[i];
        out.scalp[order[i]] = sc[i];
    }
}
} // namespace

FeatureImage rootDensity(const UvGrid& grid, const std::vector<Vec3d>& coords, const FeatureImage& region)
{
    if (coords.empty()) throw ValueError("rootDensity: no coordinates");
    const int W = grid.width, H = grid.height;
    // Summed-area tables of the points per pixel and of the region's pixels.
    std::vector<double> points((std::size_t(W) + 1) * (std::size_t(H) + 1), 0.0), inside(points.size(), 0.0);
    const auto at = [W](int x, int y) { return std::size_t(y) * (std::size_t(W) + 1) + std::size_t(x); };
    for (const Vec3d& c : coords) {
        int x, y;
        grid.pixelOf(c.x(), c.y(), x, y);
        points[at(x + 1, y + 1)] += 1.0;
    }
    std::size_t valid = 0;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x)
            if (region.isValid(x, y)) {
                inside[at(x + 1, y + 1)] = 1.0;
                ++valid;
            }
    if (valid == 0) throw ValueError("rootDensity: the region holds no valid pixel");
    for (int y = 1; y <= H; ++y)
        for (int x = 1; x <= W; ++x) {
            points[at(x, y)] += points[at(x - 1, y)] + points[at(x, y - 1)] - points[at(x - 1, y - 1)];
            inside[at(x, y)] += inside[at(x - 1, y)] + inside[at(x, y - 1)] - inside[at(x - 1, y - 1)];
        }
    // A box of (2 r + 1)² pixels holds about 32 points where the density is the mean.
    constexpr double kPointsPerBox = 32.0;
    const int r = std::max(1, int(std::lround(0.5 * (std::sqrt(kPointsPerBox * double(valid) / double(coords.size())) - 1.0))));
    FeatureImage out(W, H, 1);
    out.valid.assign(out.pixelCount(), 0);
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            if (!region.isValid(x, y)) continue;
            const int x0 = std::max(0, x - r), x1 = std::min(W, x + r + 1), y0 = std::max(0, y - r), y1 = std::min(H, y + r + 1);
            const auto sum = [&](const std::vector<double>& t) { return t[at(x1, y1)] - t[at(x0, y1)] - t[at(x1, y0)] + t[at(x0, y0)]; };
            out.pixel(x, y)[0] = float(sum(points) / sum(inside));
            out.valid[std::size_t(y) * W + x] = 1;
        }
    return out;
}

double regionArea(const ScalpMap& map, const UvGrid& grid, const FeatureImage& mask)
{
    double a = 0.0;
    for (double v : pixelAreas(map, grid, mask)) a += v;
    return a;
}

namespace {
/// Each valid pixel's weight in the draw: its world area, or with @a density its expected roots
/// (with a floor of a twentieth of the mean, which keeps every pixel of the region reachable and
/// its spacing, below, finite). @return their sum.
double pixelWeights(const std::vector<double>& area, const FeatureImage* density, std::vector<double>& weight)
{
    weight = area;
    if (density) {
        double sum = 0.0;
        std::size_t valid = 0;
        for (std::size_t p = 0; p < area.size(); ++p)
            if (area[p] > 0.0) {
                weight[p] = std::max(0.0, double(density->data[p]));
                sum += weight[p];
                ++valid;
            }
        const double floor = valid ? 0.05 * sum / double(valid) : 0.0;
        for (std::size_t p = 0; p < area.size(); ++p)
            if (area[p] > 0.0) weight[p] = std::max(weight[p], floor);
    }
    double total = 0.0;
    for (double w : weight) total += w;
    return total;
}

/// Step 3, Turk's relaxation of @a out's roots at the hexagonal spacing d of their count: over the
/// whole region (even), or per pixel from the roots expected there, count × weight / total, over
/// its area.
void relaxAtDensity(const ScalpMap& map, const UvGrid& grid, const FeatureImage& mask, const std::vector<double>& area,
                    const std::vector<double>& weight, double total, bool byDensity, int iterations, bool threaded,
                    ScatteredRoots& out)
{
    const std::size_t n = out.positions.size();
    const double evenSpacing = std::sqrt(2.0 * out.area / (std::sqrt(3.0) * double(n)));
    std::vector<double> spacing;
    if (byDensity) {
        spacing.assign(area.size(), evenSpacing);
        for (std::size_t p = 0; p < area.size(); ++p)
            if (area[p] > 0.0) spacing[p] = std::sqrt(2.0 * area[p] * total / (std::sqrt(3.0) * double(n) * weight[p]));
    }
    const auto spacingAt = [&](const Vec3d& uv) {
        if (spacing.empty()) return evenSpacing;
        int x, y;
        grid.pixelOf(uv.x(), uv.y(), x, y);
        return spacing[std::size_t(y) * grid.width + x];
    };
    relaxRoots(map, grid, mask, iterations, threaded, spacingAt, out);
}
} // namespace

ScatteredRoots scatterRoots(const ScalpMap& map, const UvGrid& grid, const FeatureImage& mask,
                            const RootScatterParams& params, bool threaded, const FeatureImage* density)
{
    if (params.count == 0) throw ValueError("scatterRoots: a count of 0 roots");
    if (density && (density->width != grid.width || density->height != grid.height || density->channels != 1))
        throw ValueError("scatterRoots: the density image is not one channel on the grid");
    // 1. Pixel weights (areas, or expected roots) and their running sum.
    const std::vector<double> area = pixelAreas(map, grid, mask);
    std::vector<double> weight;
    const double total = pixelWeights(area, density, weight);
    if (!(total > 0.0)) throw LookupError("scatterRoots: the scalp region holds no valid pixel");
    std::vector<double> cdf(weight.size());
    double running = 0.0;
    for (std::size_t i = 0; i < weight.size(); ++i) cdf[i] = (running += weight[i]);
    ScatteredRoots out;
    for (double a : area) out.area += a;
    const std::size_t n = params.count;
    out.positions.resize(n);
    out.scalp.resize(n);
    // 2. Random roots, by weight.
    forEachIndex(n, threaded, [&](std::size_t i) {
        Rng rng(params.seed, 0x700754u + params.stream, i);
        const double t = rng.uniform() * total;
        const std::size_t p = std::size_t(std::upper_bound(cdf.begin(), cdf.end(), t) - cdf.begin());
        const std::size_t pix = std::min(p, cdf.size() - 1);
        const int x = int(pix % std::size_t(grid.width)), y = int(pix / std::size_t(grid.width));
        const double u = grid.u(x + rng.uniform() - 0.5), v = grid.v(y + rng.uniform() - 0.5);
        out.scalp[i] = Vec3d(u, v, 0.0);
        out.positions[i] = map.toWorld(out.scalp[i]);
    }, 512);
    // 3. Relaxed at the spacing of the density.
    relaxAtDensity(map, grid, mask, area, weight, total, density != nullptr, params.iterations, threaded, out);
    return out;
}

ScatteredRoots scatterAroundRoots(const ScalpMap& map, const UvGrid& grid, const FeatureImage& mask,
                                  const std::vector<Vec3d>& exampleCoords, const RootScatterParams& params, bool threaded)
{
    if (params.count == 0) throw ValueError("scatterAroundRoots: a count of 0 roots");
    if (exampleCoords.empty()) throw ValueError("scatterAroundRoots: no example roots to draw around");
    const std::size_t m = exampleCoords.size(), n = params.count;
    // Each example root's reach: kAroundReach of the distance to its nearest neighbour in (u, v).
    std::vector<double> reach = nearestUvDistances(exampleCoords, threaded);
    for (double& r : reach) r *= kAroundReach;
    // The example's roots in a random order, round again while more roots are wanted.
    std::vector<std::uint32_t> order(m);
    for (std::size_t j = 0; j < m; ++j) order[j] = std::uint32_t(j);
    Rng shuffle(params.seed, 0x5c0a7u + params.stream);
    for (std::size_t j = m; j > 1; --j) std::swap(order[j - 1], order[std::min(j - 1, std::size_t(shuffle.uniform() * double(j)))]);
    ScatteredRoots out;
    const std::vector<double> area = pixelAreas(map, grid, mask);
    for (double a : area) out.area += a;
    if (!(out.area > 0.0)) throw LookupError("scatterAroundRoots: the scalp region holds no valid pixel");
    out.positions.resize(n);
    out.scalp.resize(n);
    forEachIndex(n, threaded, [&](std::size_t i) {
        Rng rng(params.seed, 0x700754u + params.stream, i);
        const Vec3d at(exampleCoords[order[i % m]].x(), exampleCoords[order[i % m]].y(), 0.0);
        const double angle = 2.0 * M_PI * rng.uniform(), r = reach[order[i % m]] * std::sqrt(rng.uniform());
        Vec3d s(at.x() + r * std::cos(angle), at.y() + r * std::sin(angle), 0.0);
        int x, y;
        grid.pixelOf(s.x(), s.y(), x, y);
        if (!mask.isValid(x, y)) s = at;  // off the region: on the example's root
        out.scalp[i] = s;
        out.positions[i] = map.toWorld(s);
    }, 512);
    // Roots drawn round again sit near one another: relaxed at the example's density.
    if (n > m) {
        const FeatureImage density = rootDensity(grid, exampleCoords, mask);
        std::vector<double> weight;
        const double total = pixelWeights(area, &density, weight);
        relaxAtDensity(map, grid, mask, area, weight, total, true, params.iterations, threaded, out);
    }
    return out;
}

} // namespace vdbhair
