#include "Follicles.h"

#include <vdbhair/Format.h>

#include <vdbhair/scalp/PointCloud.h>

#include <vdbhair/Exceptions.h>
#include <vdbhair/Progress.h>
#include <vdbhair/Random.h>
#include <vdbhair/scalp/ScalpSampler.h>

#include <openvdb/tools/Morphology.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>

namespace vdbhair {

namespace {



template<typename Fn>
void forRange(std::size_t n, bool threaded, const Fn& fn)
{
    if (threaded) tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 256), fn);
    else fn(tbb::blocked_range<std::size_t>(0, n));
}

/// The tangent of the frame: @a up projected onto the plane of @a n (x, then z, when up is
/// within 8 degrees of the normal).
Vec3d tangentFrom(const Vec3d& n, const Vec3d& up)
{
    for (const Vec3d& ref : {up, Vec3d(1, 0, 0), Vec3d(0, 0, 1)}) {
        Vec3d t = ref - n * ref.dot(n);
        const double len = t.length();
        if (len > 0.14 * ref.length()) return t / len;
    }
    return Vec3d(1, 0, 0);
}

/// Mean nearest-neighbour distance of relaxed roots over the hexagonal spacing d (measured).
constexpr double kNearestPerHexSpacing = 0.93;

/// A band voxel of the zero level set and its share of the area.
struct SurfaceCell { openvdb::Coord ijk; double weight; };

/// The area of the zero level set in the sampler's region, and its band voxels with their weights
/// (@a cells, when given): only voxels within two voxels of a sign change. A band with no zero in
/// it (both sides positive: an open part of a mesh that capping did not close, e.g. head_max4's
/// torso) has no surface to project onto; counting its area put the roots it was owed on the rest,
/// at half the spacing (measured: CV 0.52, median spacing 0.51 of the target, on head_max4 at
/// 0.5-unit voxels). Its area is returned apart, as areaWithoutZero.
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

} // namespace

ScalpArea measureScalpArea(const openvdb::FloatGrid::ConstPtr& surface, const openvdb::BoolGrid::ConstPtr& region)
{
    return surfaceCells(*surface, ScalpSampler(surface, region), nullptr);
}

Follicles sampleFollicles(const openvdb::FloatGrid::ConstPtr& surface, const openvdb::BoolGrid::ConstPtr& region,
                          const FollicleParams& params, bool threaded, openvdb::util::NullInterrupter* interrupter)
{
    const std::string where = "sampleFollicles";
    if (params.count == 0 && !(params.spacing > 0.0)) {
        throw ValueError(where + ": count 0 and no spacing: give a count of at least 1 or a positive spacing");
    }
    if (params.count > 0 && params.spacing > 0.0) throw ValueError(where + ": both a count and a spacing: give one");
    if (params.spacing < 0.0 || !std::isfinite(params.spacing)) throw ValueError(where + ": spacing " + formatNumber(params.spacing) + " must be a positive length");
    if (params.count > params.maxCount) {
        throw LimitError(where + ": count " + std::to_string(params.count) + " is more than the cap of " + std::to_string(params.maxCount) +
                         " (about " + std::to_string(params.count / 5000000 + 1) + " GB of particles and neighbour lists)");
    }
    if (params.maxIterations < 0) throw ValueError(where + ": maxIterations " + std::to_string(params.maxIterations) + " must be at least 0");
    const ScalpSampler sampler(surface, region);
    const double h = sampler.voxelSize();

    // 1. Area of the surface in the region, and the band voxels to draw from (surfaceCells).
    std::vector<SurfaceCell> cells;
    const ScalpArea measured = surfaceCells(*surface, sampler, &cells);
    const double area = measured.area, areaWithoutZero = measured.areaWithoutZero;
    if (cells.empty() || !(area > 0.0)) {
        throw LookupError(where + ": the " + std::string(region ? "region holds" : "surface has") + " no voxel of the zero level set" +
                          (areaWithoutZero > 0.0 ? " (its band never changes sign: an open or unsigned surface)" : "") + "; there is nowhere to put roots");
    }

    // 2. Target count and spacing (hexagonal packing: area sqrt(3)/2 d^2 per root).
    std::size_t count = params.count;
    double d = 0.0;
    if (count > 0) {
        d = std::sqrt(2.0 * area / (std::sqrt(3.0) * double(count)));
    } else {
        // A relaxed set's nearest-neighbour distance is below the hexagonal spacing (defects,
        // curvature): 0.93 d on spheres of 2000 roots after 200 to 700 iterations (README).
        d = params.spacing / kNearestPerHexSpacing;
        const double n = 2.0 * area / (std::sqrt(3.0) * d * d);
        if (!(n <= double(params.maxCount))) {
            throw LimitError(where + ": spacing " + formatNumber(params.spacing) + " over an area of " + formatNumber(area) + " makes about " + formatNumber(std::round(n)) +
                             " roots, more than the cap of " + std::to_string(params.maxCount));
        }
        count = std::max<std::size_t>(1, std::size_t(std::llround(n)));
    }
    Follicles out;
    out.area = area;
    out.areaWithoutZero = areaWithoutZero;
    out.targetSpacing = d;

    // 3. Initial particles: voxels drawn by weight, jittered, projected; region misses redrawn.
    std::vector<double> cumulative(cells.size());
    {
        double s = 0.0;
        for (std::size_t i = 0; i < cells.size(); ++i) cumulative[i] = (s += cells[i].weight);
    }
    std::vector<Vec3d> pos(count), next(count);
    std::vector<char> placed(count, 0);
    {
        ProgressCounter progress(interrupter, "placing roots", count, "roots");
        forRange(count, threaded, [&](const tbb::blocked_range<std::size_t>& r) {
            ScalpSampler::Local local(sampler);
            for (std::size_t i = r.begin(); i != r.end(); ++i) {
                Rng rng(params.seed, i, 0x5ca1b);
                for (int attempt = 0; attempt < 32 && !placed[i]; ++attempt) {
                    const double u = rng.uniform() * cumulative.back();
                    const std::size_t c = std::min<std::size_t>(
                        std::size_t(std::upper_bound(cumulative.begin(), cumulative.end(), u) - cumulative.begin()), cells.size() - 1);
                    const Vec3d jitter(rng.uniform() - 0.5, rng.uniform() - 0.5, rng.uniform() - 0.5);
                    const Vec3d p = local.project(surface->transform().indexToWorld(cells[c].ijk.asVec3d() + jitter));
                    if (!local.inRegion(p) || !(std::abs(local.distance(p)) < 0.01 * h)) continue;
                    pos[i] = p;
                    placed[i] = 1;
                }
            }
            if (progress.add(r.size())) return;
        });
        if (progress.stopped()) throw InterruptedError(where + ": interrupted");
    }
    {
        std::size_t k = 0;
        for (std::size_t i = 0; i < count; ++i) if (placed[i]) pos[k++] = pos[i];
        pos.resize(k);
        next.resize(k);
        count = k;
    }
    if (count == 0) throw LookupError(where + ": no root could be placed on the surface in the region");

    // 4. Relaxation: Witkin-Heckbert repulsion, all particles at once.
    const double sigma = 0.5 * d, inv2s2 = 1.0 / (2.0 * sigma * sigma);
    const double searchR2 = (4.0 * sigma) * (4.0 * sigma), maxMove = 0.25 * d;
    std::vector<double> moved(count, 0.0);
    ProgressCounter progress(interrupter, "relaxing roots", std::uint64_t(params.maxIterations), "iterations");
    int it = 0;
    // Neighbour lists (Verlet lists): each particle's neighbours within 4 sigma plus a skin, in
    // index order, from a k-d tree over the positions at the last build. A particle that has moved
    // more than half the skin since then is "fast": its neighbours come from a search around its
    // position in that tree, and every particle finds the fast ones in a small tree over their
    // current positions. Any pair within 4 sigma is found (a pair of slow particles moved less
    // than the skin together), so the forces are those of a full search per iteration, summed in
    // the same index order, bit for bit. The lists are rebuilt when more than 1/20 of the
    // particles are fast. The searches and their sort were 45 % of the time (perf, 20,000 roots on
    // head_max4); a few particles that keep jumping (thin or folded parts of a band) made a global
    // skin test rebuild every iteration on woman_head and ruby_head.
    const double skin = 0.5 * d, listR = 4.0 * sigma + skin, fastR = 4.0 * sigma + 0.5 * skin;
    std::vector<std::vector<std::uint32_t>> lists(count);
    std::vector<Vec3d> builtAt, fastPos;
    std::vector<std::uint32_t> fastIds;
    std::vector<char> fast(count, 0);
    const PointCloud builtCloud{&builtAt}, fastCloud{&fastPos};
    std::unique_ptr<PointKdTree> builtTree, fastTree;
    auto buildLists = [&] {
        builtAt = pos;
        builtTree = std::make_unique<PointKdTree>(3, builtCloud, nanoflann::KDTreeSingleIndexAdaptorParams(16));
        forRange(count, threaded, [&](const tbb::blocked_range<std::size_t>& r) {
            std::vector<std::pair<std::uint32_t, double>> nb;
            for (std::size_t i = r.begin(); i != r.end(); ++i) {
                nb.clear();
                builtTree->radiusSearch(&pos[i][0], listR * listR, nb, nanoflann::SearchParams(32, 0.f, false));
                std::vector<std::uint32_t>& list = lists[i];
                list.clear();
                for (const auto& m : nb) if (m.first != i) list.push_back(m.first);
                std::sort(list.begin(), list.end());
            }
        });
    };
    for (; it < params.maxIterations; ++it) {
        std::size_t fastCount = 0;
        if (builtAt.size() == count) {
            for (std::size_t i = 0; i < count; ++i) {
                fast[i] = (pos[i] - builtAt[i]).length() > 0.5 * skin;
                fastCount += std::size_t(fast[i]);
            }
        }
        if (builtAt.size() != count || fastCount > count / 20) {
            buildLists();
            std::fill(fast.begin(), fast.end(), 0);
            fastCount = 0;
        }
        fastIds.clear();
        fastPos.clear();
        for (std::size_t i = 0; i < count && fastCount > 0; ++i) {
            if (fast[i]) {
                fastIds.push_back(std::uint32_t(i));
                fastPos.push_back(pos[i]);
            }
        }
        fastTree.reset();
        if (fastCount > 0) fastTree = std::make_unique<PointKdTree>(3, fastCloud, nanoflann::KDTreeSingleIndexAdaptorParams(16));
        forRange(count, threaded, [&](const tbb::blocked_range<std::size_t>& r) {
            ScalpSampler::Local local(sampler);
            std::vector<std::pair<std::uint32_t, double>> nb;
            std::vector<std::uint32_t> found;
            for (std::size_t i = r.begin(); i != r.end(); ++i) {
                const std::vector<std::uint32_t>* candidates = &lists[i];
                if (fastCount > 0) {
                    found.clear();
                    if (!fast[i]) {
                        for (const std::uint32_t j : lists[i]) if (!fast[j]) found.push_back(j);
                    } else {
                        nb.clear();
                        builtTree->radiusSearch(&pos[i][0], fastR * fastR, nb, nanoflann::SearchParams(32, 0.f, false));
                        for (const auto& m : nb) if (m.first != i && !fast[m.first]) found.push_back(m.first);
                    }
                    nb.clear();
                    fastTree->radiusSearch(&pos[i][0], searchR2, nb, nanoflann::SearchParams(32, 0.f, false));
                    for (const auto& m : nb) if (fastIds[m.first] != i) found.push_back(fastIds[m.first]);
                    if (fast[i] || !nb.empty()) std::sort(found.begin(), found.end());
                    candidates = &found;
                }
                Vec3d f(0.0);
                for (const std::uint32_t j : *candidates) {
                    const Vec3d e = pos[i] - pos[j];
                    const double r2 = e.lengthSqr();
                    if (r2 < searchR2) f += e * std::exp(-r2 * inv2s2);  // sigma^2 * grad E
                }
                f *= params.stepScale;
                const Vec3d n = local.normal(pos[i]);
                f -= n * f.dot(n);
                const double len = f.length();
                if (len > maxMove) f *= maxMove / len;
                // A move must stay in the region and land on the zero level set near where it was
                // aimed (projection can run off where the band is thin or folded): else it is
                // halved, up to three times, or not taken.
                auto acceptable = [&](const Vec3d& q) {
                    return local.inRegion(q) && std::abs(local.distance(q)) < 0.01 * h && (q - pos[i]).length() < maxMove + 2.0 * h;
                };
                Vec3d p = local.project(pos[i] + f);
                for (int k = 0; k < 3 && !acceptable(p); ++k) {
                    f *= 0.5;
                    p = local.project(pos[i] + f);
                }
                if (!acceptable(p)) p = pos[i];
                next[i] = p;
                moved[i] = (p - pos[i]).length();
            }
        });
        pos.swap(next);
        double worst = 0.0;
        for (double m : moved) worst = std::max(worst, m);
        out.lastMove = worst / d;
        if (progress.add(1)) throw InterruptedError(where + ": interrupted");
        if (worst < params.tolerance * d) { ++it; break; }
    }
    progress.finish();
    out.iterations = it;

    // 5. Death: a particle within 0.1 d of an earlier one is removed (they have no force between
    // them once they coincide, which projection onto thin or folded parts of a band can cause).
    {
        const PointCloud cloud{&pos};
        const PointKdTree tree(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(16));
        std::vector<char> alive(count, 1);
        std::vector<std::pair<std::uint32_t, double>> nb;
        const double r2 = (0.1 * d) * (0.1 * d);
        for (std::size_t i = 0; i < count; ++i) {
            nb.clear();
            tree.radiusSearch(&pos[i][0], r2, nb, nanoflann::SearchParams(32, 0.f, false));
            for (const auto& m : nb) {
                if (m.first < i && alive[m.first]) { alive[i] = 0; break; }
            }
        }
        std::size_t k = 0;
        for (std::size_t i = 0; i < count; ++i) if (alive[i]) pos[k++] = pos[i];
        out.removed = count - k;
        pos.resize(k);
        count = k;
    }

    // 6. Frames.
    out.positions.resize(count);
    out.normals.resize(count);
    out.tangents.resize(count);
    const Vec3d up = params.up.length() > 0.0 ? params.up / params.up.length() : Vec3d(0, 1, 0);
    forRange(count, threaded, [&](const tbb::blocked_range<std::size_t>& r) {
        ScalpSampler::Local local(sampler);
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
            const Vec3d n = local.normal(pos[i]);
            out.positions[i] = Vec3f(pos[i]);
            out.normals[i] = Vec3f(n);
            out.tangents[i] = Vec3f(tangentFrom(n, up));
        }
    });
    return out;
}

FollicleStats measureFollicles(const std::vector<Vec3f>& positions, const openvdb::FloatGrid::ConstPtr& surface)
{
    FollicleStats s;
    s.count = positions.size();
    if (positions.size() >= 2) {
        std::vector<Vec3d> pts(positions.begin(), positions.end());
        const PointCloud cloud{&pts};
        const PointKdTree tree(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(16));
        std::vector<double> nn(pts.size());
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, pts.size(), 1024), [&](const tbb::blocked_range<std::size_t>& r) {
            for (std::size_t i = r.begin(); i != r.end(); ++i) {
                std::uint32_t idx[2];
                double d2[2];
                const std::size_t k = tree.knnSearch(&pts[i][0], 2, idx, d2);
                double best = std::numeric_limits<double>::max();
                for (std::size_t m = 0; m < k; ++m) if (idx[m] != i) best = std::min(best, d2[m]);
                nn[i] = std::sqrt(best);
            }
        });
        double sum = 0.0, sum2 = 0.0;
        s.nnMin = std::numeric_limits<double>::max();
        for (double v : nn) {
            sum += v;
            s.nnMin = std::min(s.nnMin, v);
            s.nnMax = std::max(s.nnMax, v);
        }
        s.nnMean = sum / double(nn.size());
        for (double v : nn) sum2 += (v - s.nnMean) * (v - s.nnMean);
        s.nnCV = s.nnMean > 0.0 ? std::sqrt(sum2 / double(nn.size())) / s.nnMean : 0.0;
    }
    if (surface) {
        const ScalpSampler sampler(surface);
        for (const Vec3f& p : positions) {
            s.maxSurfaceDistanceVoxels = std::max(s.maxSurfaceDistanceVoxels, std::abs(sampler.distance(Vec3d(p))) / sampler.voxelSize());
        }
    }
    return s;
}

} // namespace vdbhair
