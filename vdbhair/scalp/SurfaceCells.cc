#include "SurfaceCells.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/Parallel.h>
#include <vdbhair/strands/PointCloud.h>

#include <openvdb/tools/Morphology.h>

#include <tbb/blocked_range.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <unordered_map>

namespace vdbhair {

ScalpArea surfaceCells(const openvdb::FloatGrid& surface, const ScalpSampler& sampler, std::vector<SurfaceCell>* cells)
{
    const double h = sampler.voxelSize();
    openvdb::BoolGrid::Ptr nearZero = openvdb::BoolGrid::create(false);
    {
        auto acc = surface.getConstAccessor();
        auto mark = nearZero->getAccessor();
        for (auto it = surface.cbeginValueOn(); it; ++it) {
            if (!it.isVoxelValue()) continue;
            const float phi = *it;
            const openvdb::Coord ijk = it.getCoord();
            for (int a = 0; a < 3; ++a) {
                openvdb::Coord n = ijk;
                n[a] += 1;
                const float q = acc.getValue(n);
                if ((phi < 0.f) != (q < 0.f)) {  // zeros count with the outside: an unsigned band has exact zeros too
                    mark.setValueOn(ijk);
                    mark.setValueOn(n);
                }
            }
        }
        openvdb::tools::dilateActiveValues(nearZero->tree(), 2, openvdb::tools::NN_FACE_EDGE_VERTEX, openvdb::tools::IGNORE_TILES);
    }
    const double eps = 1.5 * h;
    ScalpArea out;
    auto nearAcc = nearZero->getConstAccessor();
    for (auto it = surface.cbeginValueOn(); it; ++it) {
        const double phi = double(*it);
        if (!(std::abs(phi) < eps)) continue;
        if (!it.isVoxelValue()) continue;
        const openvdb::Coord ijk = it.getCoord();
        if (!sampler.inRegion(surface.transform().indexToWorld(ijk))) continue;
        const double w = (1.0 + std::cos(M_PI * phi / eps)) / (2.0 * eps) * h * h * h;
        if (!nearAcc.isValueOn(ijk)) {
            out.areaWithoutZero += w;
            continue;
        }
        if (cells) cells->push_back({ijk, w});
        out.area += w;
    }
    return out;
}

std::vector<Vec3d> contourParticles(const openvdb::FloatGrid& surface, const ScalpSampler& sampler, const std::vector<SurfaceCell>& cells,
                                    double spacing, bool threaded, openvdb::util::NullInterrupter* interrupter)
{
    const double h = sampler.voxelSize();
    constexpr std::size_t kChunk = 1024;
    const std::size_t chunks = (cells.size() + kChunk - 1) / kChunk;
    std::vector<std::vector<Vec3d>> found(chunks);
    const openvdb::math::Transform& xf = surface.transform();
    forEachRange(chunks, threaded, 256, [&](const tbb::blocked_range<std::size_t>& r) {
        ScalpSampler::Local local(sampler);
        const auto onSurface = [&](const Vec3d& q) { return std::abs(local.distance(q)) < 0.01 * h; };
        for (std::size_t chunk = r.begin(); chunk != r.end(); ++chunk) {
            if (interrupter && interrupter->wasInterrupted()) return;
            for (std::size_t c = chunk * kChunk; c < std::min(cells.size(), (chunk + 1) * kChunk); ++c) {
                const Vec3d pa = local.project(xf.indexToWorld(cells[c].ijk));
                if (!onSurface(pa) || !local.inRegion(pa)) continue;
                for (int axis = 0; axis < 3; ++axis) {
                    for (int sgn = -1; sgn <= 1; sgn += 2) {
                        Vec3d step(0.0);
                        step[axis] = sgn * h;
                        Vec3d lo = pa, hi = local.project(pa + step);
                        if (!onSurface(hi) || local.inRegion(hi) || (hi - lo).length() > 3.0 * h) continue;
                        for (int k = 0; k < 12; ++k) {
                            const Vec3d mid = local.project(0.5 * (lo + hi));
                            if (!onSurface(mid)) break;
                            (local.inRegion(mid) ? lo : hi) = mid;
                        }
                        found[chunk].push_back(lo);
                    }
                }
            }
        }
    });
    if (interrupter && interrupter->wasInterrupted()) throw InterruptedError("sampleFollicles: interrupted");
    std::vector<Vec3d> points;
    for (const std::vector<Vec3d>& f : found) points.insert(points.end(), f.begin(), f.end());
    std::vector<Vec3d> kept;
    if (points.empty()) return kept;

    const PointCloud cloud{&points};
    const PointKdTree tree(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(16));
    std::vector<char> visited(points.size(), 0);
    // Kept points in a hash of cells of side `spacing`: a new point is checked against 27 cells.
    const auto key = [&](const Vec3d& p, int dx, int dy, int dz) {
        const auto q = [&](double v, int o) { return std::uint64_t(std::int64_t(std::floor(v / spacing)) + o) & 0x1fffff; };
        return (q(p.x(), dx) << 42) | (q(p.y(), dy) << 21) | q(p.z(), dz);
    };
    std::unordered_map<std::uint64_t, std::vector<std::uint32_t>> grid;
    const auto farFromKept = [&](const Vec3d& p) {
        for (int dx = -1; dx <= 1; ++dx)
            for (int dy = -1; dy <= 1; ++dy)
                for (int dz = -1; dz <= 1; ++dz) {
                    const auto cell = grid.find(key(p, dx, dy, dz));
                    if (cell == grid.end()) continue;
                    for (const std::uint32_t k : cell->second) if ((kept[k] - p).length() < spacing) return false;
                }
        return true;
    };
    std::vector<std::pair<std::uint32_t, double>> nb;
    for (std::size_t start = 0; start < points.size(); ++start) {
        for (std::size_t cur = start; !visited[cur];) {
            visited[cur] = 1;
            if (farFromKept(points[cur])) {
                grid[key(points[cur], 0, 0, 0)].push_back(std::uint32_t(kept.size()));
                kept.push_back(points[cur]);
            }
            nb.clear();
            tree.radiusSearch(&points[cur][0], 4.0 * h * h, nb, nanoflann::SearchParams(32, 0.f, true));  // sorted by distance
            for (const auto& m : nb) {
                if (!visited[m.first]) { cur = m.first; break; }
            }
        }
    }
    return kept;
}

} // namespace vdbhair
