#include "Follicles.h"

#include <vdbhair/Format.h>

#include <vdbhair/strands/PointCloud.h>

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
#include <unordered_map>

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

/// Radii stay within these multiples of the desired radius sigma_hat (a particle alone on a
/// surface grows until it fissions; one squeezed shrinks until it dies).
constexpr double kMinRadius = 0.05, kMaxRadius = 4.0;

/// Pairs interact within kCut radii (exp(-kCut^2 / 2) = 0.011 of the energy at contact). 4 took
/// 1.4 times as long for the same spread (woman_head, 30,000 roots: CV 0.0572 at 4, 0.0576 at 3;
/// 10.0 s against 7.2 s).
constexpr double kCut = 3.0, kCut2 = kCut * kCut;
/// exp(-kCut^2 / 2): each pair's weight is shifted by it, so forces vanish at the cut.
const double kCutEnergy = std::exp(-0.5 * kCut2);

/// Free particles keep this share of the contour's spacing from every contour particle: the
/// others' pressure pushed them into the gaps of the contour line (measured on a cap of the unit
/// sphere: NN CV 0.12 without, 0.05 at 0.65-0.8; on woman_head in straight.hair's region at 3,000
/// roots 0.10 without, 0.056 at 0.8). A particle of the next row, at the hexagonal place, is a
/// full spacing from them.
constexpr double kContourClearance = 0.8;

/// The region's contour on the surface, as fixed particles about @a spacing apart. Every pair of
/// face neighbours (a in the region, b out of it, both on the surface's band near zero) gives a
/// rim point: the segment between their projections onto the zero level set is bisected (12
/// times, each midpoint projected) to where the region ends, keeping the last point inside. The
/// points are walked as nearest-neighbour chains (next: the nearest unvisited point within two
/// voxels) and a point is kept when it is at least @a spacing from every point kept before, so
/// along a rim the kept points are @a spacing to @a spacing plus a voxel apart. Serial order
/// throughout: the same points for any thread count.
std::vector<Vec3d> contourParticles(const openvdb::FloatGrid& surface, const ScalpSampler& sampler, const std::vector<SurfaceCell>& cells,
                                    double spacing, bool threaded, openvdb::util::NullInterrupter* interrupter)
{
    const double h = sampler.voxelSize();
    constexpr std::size_t kChunk = 1024;
    const std::size_t chunks = (cells.size() + kChunk - 1) / kChunk;
    std::vector<std::vector<Vec3d>> found(chunks);
    const openvdb::math::Transform& xf = surface.transform();
    forRange(chunks, threaded, [&](const tbb::blocked_range<std::size_t>& r) {
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

/// Births and deaths of one control step (populationControl).
struct PopulationChange { std::size_t fissions = 0, deaths = 0; };

/// Witkin & Heckbert's fission and death, then the count: among the free particles (from
/// @a fixedCount on) near equilibrium (moved less than a quarter of their radius this iteration),
/// one whose radius exceeds fissionRatio sigma_hat splits; one below deathRatio sigma_hat dies
/// with probability 1 - sigma / (deathRatio sigma_hat). Then, if the population would still
/// differ from @a target, the free particles with the largest radii (the sparsest places) split,
/// at most half of them, or those with the smallest (the most crowded) die, at most a quarter.
/// A split replaces the particle by two at +-sigma/2 along a random tangent direction, each of
/// radius sigma / sqrt(2), the new one appended; random draws come from the stream (seed,
/// particle id, iteration), so the result does not depend on the thread count.
PopulationChange populationControl(const ScalpSampler& sampler, const FollicleParams& params, int iteration, std::size_t target, std::size_t fixedCount,
                                   double sigmaHat, const std::vector<double>& moved, const std::vector<double>& fixedGap, double clearance2,
                                   std::vector<Vec3d>& pos, std::vector<double>& sig,
                                   std::vector<std::uint64_t>& ids, std::uint64_t& nextId)
{
    const std::size_t m = pos.size();
    std::vector<char> split(m, 0), die(m, 0);
    const double sigmaSplit = params.fissionRatio * sigmaHat, sigmaDie = params.deathRatio * sigmaHat;
    std::size_t nSplit = 0, nDie = 0;
    for (std::size_t i = fixedCount; i < m; ++i) {
        if (fixedGap[i] < clearance2) {  // in a gap of the contour line: no room there
            die[i] = 1;
            ++nDie;
            continue;
        }
        if (!(moved[i] < 0.25 * sig[i])) continue;
        if (sig[i] > sigmaSplit) {
            split[i] = 1;
            ++nSplit;
        } else if (sig[i] < sigmaDie && Rng(params.seed, ids[i], 0xdead0000ull + std::uint64_t(iteration)).uniform() > sig[i] / sigmaDie) {
            die[i] = 1;
            ++nDie;
        }
    }
    const std::int64_t deficit = std::int64_t(target) - std::int64_t(m + nSplit - nDie);
    if (deficit != 0 && m > fixedCount) {
        std::vector<std::uint32_t> order;
        for (std::size_t i = fixedCount; i < m; ++i) if (!split[i] && !die[i]) order.push_back(std::uint32_t(i));
        const bool grow = deficit > 0;
        std::stable_sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) { return grow ? sig[a] > sig[b] : sig[a] < sig[b]; });
        const std::size_t freeCount = m - fixedCount;
        const std::size_t k = std::min<std::size_t>({std::size_t(grow ? deficit : -deficit), grow ? (freeCount + 1) / 2 : (freeCount + 3) / 4, order.size()});
        for (std::size_t q = 0; q < k; ++q) {
            if (grow) { split[order[q]] = 1; ++nSplit; }
            else { die[order[q]] = 1; ++nDie; }
        }
    }
    PopulationChange change;
    if (nSplit + nDie == 0) return change;
    ScalpSampler::Local local(sampler);
    const double h = sampler.voxelSize();
    const auto onSurface = [&](const Vec3d& q) { return local.inRegion(q) && std::abs(local.distance(q)) < 0.01 * h; };
    std::vector<Vec3d> newPos, childPos;
    std::vector<double> newSig, childSig;
    std::vector<std::uint64_t> newIds, childIds;
    newPos.reserve(m + nSplit);
    for (std::size_t i = 0; i < m; ++i) {
        if (die[i]) { ++change.deaths; continue; }
        if (!split[i]) {
            newPos.push_back(pos[i]);
            newSig.push_back(sig[i]);
            newIds.push_back(ids[i]);
            continue;
        }
        const Vec3d n = local.normal(pos[i]);
        Rng rng(params.seed, ids[i], 0xf1550000ull + std::uint64_t(iteration));
        Vec3d a = pos[i], b = pos[i];
        bool done = false;
        for (int attempt = 0; attempt < 4 && !done; ++attempt) {
            double x, y, z, w;
            rng.normalPair(x, y);
            rng.normalPair(z, w);
            Vec3d t(x, y, z);
            t -= n * t.dot(n);
            if (!(t.length() > 1e-6)) continue;
            t *= 0.5 * sig[i] / t.length();
            const Vec3d pa = local.project(pos[i] + t), pb = local.project(pos[i] - t);
            const bool okA = onSurface(pa), okB = onSurface(pb);
            if (okA && okB) { a = pa; b = pb; done = true; }
            else if (okA) { b = pa; done = true; }  // at the region's edge: one step inward only
            else if (okB) { b = pb; done = true; }
        }
        const double s = done ? sig[i] / std::sqrt(2.0) : sig[i];
        newPos.push_back(a);
        newSig.push_back(s);
        newIds.push_back(ids[i]);
        if (!done) continue;
        childPos.push_back(b);
        childSig.push_back(s);
        childIds.push_back(nextId++);
        ++change.fissions;
    }
    newPos.insert(newPos.end(), childPos.begin(), childPos.end());
    newSig.insert(newSig.end(), childSig.begin(), childSig.end());
    newIds.insert(newIds.end(), childIds.begin(), childIds.end());
    pos.swap(newPos);
    sig.swap(newSig);
    ids.swap(newIds);
    return change;
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
    const auto positive = [&](const char* name, double v) {
        if (!(v > 0.0) || !std::isfinite(v)) throw ValueError(where + ": " + name + " " + formatNumber(v) + " must be positive and finite");
    };
    positive("alpha", params.alpha);
    positive("energyRatio", params.energyRatio);
    positive("beta", params.beta);
    if (!(params.feedback >= 0.0) || !std::isfinite(params.feedback)) throw ValueError(where + ": feedback " + formatNumber(params.feedback) + " must be at least 0");
    if (!(params.radiusStep >= 0.0 && params.radiusStep <= 0.2)) throw ValueError(where + ": radiusStep " + formatNumber(params.radiusStep) + " must be in [0, 0.2] (the radius equation is unstable above)");
    if (!(params.fissionRatio > 1.0) || !std::isfinite(params.fissionRatio)) throw ValueError(where + ": fissionRatio " + formatNumber(params.fissionRatio) + " must be above 1");
    if (!(params.deathRatio > 0.0 && params.deathRatio < 1.0)) throw ValueError(where + ": deathRatio " + formatNumber(params.deathRatio) + " must be in (0, 1)");
    if (params.controlInterval < 0 || params.settleIterations < 0) throw ValueError(where + ": controlInterval and settleIterations must be at least 0");
    if (!(params.initialFraction > 0.0 && params.initialFraction <= 4.0)) throw ValueError(where + ": initialFraction " + formatNumber(params.initialFraction) + " must be in (0, 4]");
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
        // curvature): kRelaxedNearestPerSpacing d (Follicles.h).
        d = params.spacing / kRelaxedNearestPerSpacing;
        const double n = 2.0 * area / (std::sqrt(3.0) * d * d);
        if (!(n <= double(params.maxCount))) {
            throw LimitError(where + ": spacing " + formatNumber(params.spacing) + " over an area of " + formatNumber(area) + " makes about " + formatNumber(std::round(n)) +
                             " roots, more than the cap of " + std::to_string(params.maxCount));
        }
        count = std::max<std::size_t>(1, std::size_t(std::llround(n)));
    }
    const std::size_t targetCount = count;
    Follicles out;
    out.area = area;
    out.areaWithoutZero = areaWithoutZero;
    out.targetSpacing = d;

    // 3. Fixed particles on the region's contour, at the relaxed spacing (contourParticles).
    const double sigmaHat = 0.5 * d;
    std::vector<Vec3d> pos;
    if (region && params.contour) pos = contourParticles(*surface, sampler, cells, kRelaxedNearestPerSpacing * d, threaded, interrupter);
    const std::size_t fixedCount = pos.size();
    const double clearance2 = std::pow(kContourClearance * kRelaxedNearestPerSpacing * d, 2);
    out.contour = fixedCount;

    // 4. Initial free particles: voxels drawn by weight, jittered, projected; region misses
    // redrawn. A share f of the free count starts, with radius sigma_hat / sqrt(f) (their density).
    const std::size_t freeTarget = count > fixedCount ? count - fixedCount : 0;
    const std::size_t initial = freeTarget == 0 ? 0 : std::max<std::size_t>(1, std::size_t(std::llround(params.initialFraction * double(freeTarget))));
    if (initial > params.maxCount) throw LimitError(where + ": " + std::to_string(initial) + " initial particles (initialFraction " + formatNumber(params.initialFraction) + ") is more than the cap of " + std::to_string(params.maxCount));
    std::vector<double> cumulative(cells.size());
    {
        double s = 0.0;
        for (std::size_t i = 0; i < cells.size(); ++i) cumulative[i] = (s += cells[i].weight);
    }
    std::vector<Vec3d> fixedPos(pos.begin(), pos.end());
    const PointCloud fixedCloud{&fixedPos};
    std::unique_ptr<PointKdTree> fixedTree;
    if (fixedCount > 0) fixedTree = std::make_unique<PointKdTree>(3, fixedCloud, nanoflann::KDTreeSingleIndexAdaptorParams(16));
    {
        std::vector<Vec3d> drawn(initial);
        std::vector<char> placed(initial, 0);
        ProgressCounter progress(interrupter, "placing roots", initial, "roots");
        forRange(initial, threaded, [&](const tbb::blocked_range<std::size_t>& r) {
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
                    if (fixedTree) {  // not in a gap of the contour line
                        std::uint32_t idx;
                        double d2;
                        const double q[3] = {p.x(), p.y(), p.z()};
                        fixedTree->knnSearch(q, 1, &idx, &d2);
                        if (d2 < clearance2) continue;
                    }
                    drawn[i] = p;
                    placed[i] = 1;
                }
            }
            if (progress.add(r.size())) return;
        });
        if (progress.stopped()) throw InterruptedError(where + ": interrupted");
        for (std::size_t i = 0; i < initial; ++i) if (placed[i]) pos.push_back(drawn[i]);
    }
    if (pos.empty()) throw LookupError(where + ": no root could be placed on the surface in the region");
    out.initial = pos.size() - fixedCount;
    std::vector<double> sig(pos.size(), sigmaHat);
    if (params.initialFraction > 0.0 && params.initialFraction != 1.0) {
        const double s0 = sigmaHat * std::sqrt(double(freeTarget) / double(std::max<std::size_t>(1, initial)));
        std::fill(sig.begin() + std::ptrdiff_t(fixedCount), sig.end(), std::clamp(s0, kMinRadius * sigmaHat, kMaxRadius * sigmaHat));
    }
    std::vector<std::uint64_t> ids(pos.size());
    for (std::size_t i = 0; i < ids.size(); ++i) ids[i] = i;
    std::uint64_t nextId = ids.size();
    count = pos.size();

    // 5. Relaxation: Witkin-Heckbert repulsion and radius feedback, all particles at once, with
    // fission and death every controlInterval iterations.
    const double alpha = params.alpha, eHat = params.energyRatio * params.alpha;
    const double moveScale = params.stepScale / (2.0 * alpha);  // uniform radii: stepScale sigma^2 grad E
    // Interactions use radii of at most sigmaCap (the fission threshold), so the neighbour lists
    // have one radius for the whole run: a particle beyond it splits at its next control step,
    // and one that cannot (alone on a scrap of surface too small for two) would otherwise widen
    // every particle's search.
    const double sigmaCap = params.fissionRatio * sigmaHat;
    std::vector<Vec3d> next(count);
    std::vector<double> nextSig(count), moved(count, 0.0), fixedGap(count, std::numeric_limits<double>::max());
    ProgressCounter progress(interrupter, "relaxing roots", std::uint64_t(params.maxIterations), "iterations");
    int it = 0;
    // Neighbour lists (Verlet lists): each particle's neighbours within kCut sigmaCap plus a skin, in
    // index order, from a k-d tree over the positions at the last build. A particle that has moved
    // more than half the skin since then is "fast": its neighbours come from a search around its
    // position in that tree, and every particle finds the fast ones in a small tree over their
    // current positions. Any pair within kCut sigmaCap is found (a pair of slow particles moved less
    // than the skin together), so the forces are those of a full search per iteration, summed in
    // the same index order, bit for bit. The lists are rebuilt when more than 1/20 of the
    // particles are fast and when particles are born or die. The searches and their sort were 45 % of the time (perf, 20,000 roots on head_max4);
    // a few particles that keep jumping (thin or folded parts of a band) made a global skin test
    // rebuild every iteration on woman_head and ruby_head.
    const double skin = 0.5 * d;
    std::vector<std::vector<std::uint32_t>> lists;
    std::vector<Vec3d> builtAt, fastPos;
    std::vector<std::uint32_t> fastIds;
    std::vector<char> fast;
    const PointCloud builtCloud{&builtAt}, fastCloud{&fastPos};
    std::unique_ptr<PointKdTree> builtTree, fastTree;
    auto buildLists = [&] {
        builtAt = pos;
        lists.assign(count, {});
        const double listR = kCut * sigmaCap + skin;
        builtTree = std::make_unique<PointKdTree>(3, builtCloud, nanoflann::KDTreeSingleIndexAdaptorParams(16));
        forRange(count, threaded, [&](const tbb::blocked_range<std::size_t>& r) {
            std::vector<std::pair<std::uint32_t, double>> nb;
            for (std::size_t i = r.begin(); i != r.end(); ++i) {
                nb.clear();
                builtTree->radiusSearch(&pos[i][0], listR * listR, nb, nanoflann::SearchParams(32, 0.f, false));
                std::vector<std::uint32_t>& list = lists[i];
                for (const auto& m : nb) if (m.first != i) list.push_back(m.first);
                std::sort(list.begin(), list.end());
            }
        });
    };
    std::size_t lastControlChange = 0;
    for (; it < params.maxIterations; ++it) {
        const double searchR2 = (kCut * sigmaCap) * (kCut * sigmaCap), fastR = kCut * sigmaCap + 0.5 * skin;
        std::size_t fastCount = 0;
        fast.assign(count, 0);
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
                if (i < fixedCount) {
                    next[i] = pos[i];
                    nextSig[i] = sig[i];
                    moved[i] = 0.0;
                    continue;
                }
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
                // Witkin & Heckbert: E_i = sum_j alpha exp(-r^2 / 2 sigma_i^2) (cut at kCut sigma_i),
                // the move sigma_i^2 sum_j r_ij (E_ij / sigma_i^2 + E_ji / sigma_j^2), and
                // dE_i / dsigma_i for the radius feedback.
                const double si = std::min(sig[i], sigmaCap), si2 = si * si;
                Vec3d force(0.0);
                double energy = 0.0, dEnergy = 0.0;
                for (const std::uint32_t j : *candidates) {
                    const Vec3d e = pos[i] - pos[j];
                    const double sjc = std::min(sig[j], sigmaCap);
                    const double r2 = e.lengthSqr(), sj2 = sjc * sjc;
                    double w = 0.0;
                    // Shifted at the cut (kCutEnergy): the force falls to 0 there instead of
                    // jumping, which kept particles jittering by 0.01 d for good.
                    if (r2 < kCut2 * si2) {
                        const double eij = alpha * std::exp(-r2 / (2.0 * si2));
                        energy += eij - alpha * kCutEnergy;
                        dEnergy += r2 * eij;
                        w += eij - alpha * kCutEnergy;
                    }
                    if (r2 < kCut2 * sj2) w += si2 / sj2 * alpha * (std::exp(-r2 / (2.0 * sj2)) - kCutEnergy);
                    force += e * w;
                }
                dEnergy /= si2 * si;
                Vec3d f = force * moveScale;
                const Vec3d n = local.normal(pos[i]);
                f -= n * f.dot(n);
                const double maxMove = 0.5 * si;  // d / 4 at the desired radius
                const double len = f.length();
                if (len > maxMove) f *= maxMove / len;
                // A move must stay in the region and land on the zero level set near where it was
                // aimed (projection can run off where the band is thin or folded): else it is
                // halved, up to three times, or not taken.
                // Nor may it come closer to a contour particle than kContourClearance of the
                // contour's spacing, unless it was closer already and moves away.
                double nearFixed = std::numeric_limits<double>::max();
                for (const std::uint32_t j : *candidates) {
                    if (j >= fixedCount) break;  // index order: the fixed come first
                    nearFixed = std::min(nearFixed, (pos[i] - pos[j]).lengthSqr());
                }
                fixedGap[i] = nearFixed;
                auto clearOfContour = [&](const Vec3d& q) {
                    if (nearFixed >= clearance2 * 16.0) return true;
                    double m = std::numeric_limits<double>::max();
                    for (const std::uint32_t j : *candidates) {
                        if (j >= fixedCount) break;
                        m = std::min(m, (q - pos[j]).lengthSqr());
                    }
                    return m >= clearance2 || m >= nearFixed;
                };
                auto acceptable = [&](const Vec3d& q) {
                    return local.inRegion(q) && std::abs(local.distance(q)) < 0.01 * h && (q - pos[i]).length() < maxMove + 2.0 * h && clearOfContour(q);
                };
                Vec3d p = local.project(pos[i] + f);
                for (int k = 0; k < 3 && !acceptable(p); ++k) {
                    f *= 0.5;
                    p = local.project(pos[i] + f);
                }
                if (!acceptable(p)) p = pos[i];
                next[i] = p;
                moved[i] = (p - pos[i]).length();
                // Radius feedback: dsigma/dt = -rho (E_i - E_hat) / (dE_i/dsigma_i + beta / sigma_hat).
                double ds = params.radiusStep * -params.feedback * (energy - eHat) / (dEnergy + params.beta / sigmaHat);
                ds = std::clamp(ds, -0.1 * si, 0.1 * si);
                nextSig[i] = std::clamp(sig[i] + ds, kMinRadius * sigmaHat, kMaxRadius * sigmaHat);
            }
        });
        pos.swap(next);
        sig.swap(nextSig);
        double worst = 0.0;
        for (double m : moved) worst = std::max(worst, m);
        out.lastMove = worst / d;
        if (progress.add(1)) throw InterruptedError(where + ": interrupted");
        const bool settled = worst < params.tolerance * d;
        // Fission and death (populationControl), not in the last settleIterations.
        const bool mayControl = params.controlInterval > 0 && it + 1 + params.settleIterations <= params.maxIterations;
        if (mayControl && (settled || (it + 1) % params.controlInterval == 0)) {
            const PopulationChange change = populationControl(sampler, params, it, targetCount, fixedCount, sigmaHat, moved, fixedGap, clearance2, pos, sig, ids, nextId);
            out.fissions += change.fissions;
            out.deaths += change.deaths;
            if (change.fissions + change.deaths > 0) {
                count = pos.size();
                next.resize(count);
                nextSig.resize(count);
                moved.assign(count, 0.0);
                fixedGap.assign(count, std::numeric_limits<double>::max());
                builtAt.clear();  // rebuild the lists
                lastControlChange = std::size_t(it + 1);
                continue;
            }
        }
        if (settled) { ++it; break; }
    }
    progress.finish();
    out.iterations = it;
    out.lastPopulationChange = int(lastControlChange);
    out.radiusSpread = 0.0;
    if (count > fixedCount) {
        const auto [lo, hi] = std::minmax_element(sig.begin() + std::ptrdiff_t(fixedCount), sig.end());
        out.radiusSpread = (*hi - *lo) / sigmaHat;
    }

    // 6. Death: a particle within 0.1 d of an earlier one is removed (they have no force between
    // them once they coincide, which projection onto thin or folded parts of a band can cause).
    {
        const PointCloud cloud{&pos};
        const PointKdTree tree(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(16));
        std::vector<char> alive(count, 1);
        std::vector<std::pair<std::uint32_t, double>> nb;
        const double r2 = (0.1 * d) * (0.1 * d);
        for (std::size_t i = fixedCount; i < count; ++i) {
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

    // 7. Frames.
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
