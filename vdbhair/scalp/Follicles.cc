#include "Follicles.h"

#include <vdbhair/Format.h>

#include <vdbhair/strands/PointCloud.h>

#include <vdbhair/Exceptions.h>
#include <vdbhair/Progress.h>
#include <vdbhair/Random.h>
#include <vdbhair/scalp/ScalpSampler.h>
#include <vdbhair/scalp/SurfaceCells.h>

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

/// The checks of sampleFollicles()'s parameters, before any work.
void checkFollicleParams(const FollicleParams& params, const std::string& where)
{
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
}

/// Step 2, the target count and spacing @a d (hexagonal packing: area sqrt(3)/2 d^2 per root):
/// the count asked for, or the count that the spacing asked for makes over @a area.
std::size_t targetCount(const FollicleParams& params, double area, const std::string& where, double& d)
{
    std::size_t count = params.count;
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
    return count;
}

/// One sampleFollicles() call: its inputs and the particles, the fixed (contour) ones first.
struct FollicleRun
{
    FollicleRun(const openvdb::FloatGrid& grid, const ScalpSampler& scalp, const FollicleParams& p, bool runThreaded,
                openvdb::util::NullInterrupter* interrupt, const std::string& place, double spacing, std::size_t target)
        : surface(grid), sampler(scalp), params(p), threaded(runThreaded), interrupter(interrupt), where(place), h(scalp.voxelSize()),
          d(spacing), sigmaHat(0.5 * spacing), targetCount(target)
    {
    }

    const openvdb::FloatGrid& surface;
    const ScalpSampler& sampler;
    const FollicleParams& params;
    const bool threaded;
    openvdb::util::NullInterrupter* const interrupter;
    const std::string& where;
    const double h;               ///< the sampler's voxel size
    const double d, sigmaHat;     ///< target spacing; desired radius (d / 2)
    const std::size_t targetCount;
    std::size_t fixedCount = 0;   ///< contour particles
    double clearance2 = 0.0;      ///< squared distance free particles keep from contour particles
    std::vector<Vec3d> pos;
    std::vector<double> sig;      ///< radii
    std::vector<std::uint64_t> ids;  ///< random-stream ids (populationControl())
    std::uint64_t nextId = 0;
    std::size_t count = 0;        ///< particles, fixed and free
};

/// Step 4, initial free particles: voxels drawn by weight, jittered, projected; region misses
/// redrawn. A share f of the free count starts, with radius sigma_hat / sqrt(f) (their density).
void placeInitialParticles(FollicleRun& run, const std::vector<SurfaceCell>& cells, Follicles& out)
{
    const FollicleParams& params = run.params;
    const std::string& where = run.where;
    const std::size_t fixedCount = run.fixedCount, count = run.targetCount;
    const double h = run.h, sigmaHat = run.sigmaHat, clearance2 = run.clearance2;
    std::vector<Vec3d>& pos = run.pos;
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
        ProgressCounter progress(run.interrupter, "placing roots", initial, "roots");
        forRange(initial, run.threaded, [&](const tbb::blocked_range<std::size_t>& r) {
            ScalpSampler::Local local(run.sampler);
            for (std::size_t i = r.begin(); i != r.end(); ++i) {
                Rng rng(params.seed, i, 0x5ca1b);
                for (int attempt = 0; attempt < 32 && !placed[i]; ++attempt) {
                    const double u = rng.uniform() * cumulative.back();
                    const std::size_t c = std::min<std::size_t>(
                        std::size_t(std::upper_bound(cumulative.begin(), cumulative.end(), u) - cumulative.begin()), cells.size() - 1);
                    const Vec3d jitter(rng.uniform() - 0.5, rng.uniform() - 0.5, rng.uniform() - 0.5);
                    const Vec3d p = local.project(run.surface.transform().indexToWorld(cells[c].ijk.asVec3d() + jitter));
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
    std::vector<double>& sig = run.sig;
    sig.assign(pos.size(), sigmaHat);
    if (params.initialFraction > 0.0 && params.initialFraction != 1.0) {
        const double s0 = sigmaHat * std::sqrt(double(freeTarget) / double(std::max<std::size_t>(1, initial)));
        std::fill(sig.begin() + std::ptrdiff_t(fixedCount), sig.end(), std::clamp(s0, kMinRadius * sigmaHat, kMaxRadius * sigmaHat));
    }
    std::vector<std::uint64_t>& ids = run.ids;
    ids.resize(pos.size());
    for (std::size_t i = 0; i < ids.size(); ++i) ids[i] = i;
    run.nextId = ids.size();
    run.count = pos.size();
}

/// The state of step 5, the relaxation: its constants, the particles' next positions and radii,
/// and neighbour lists (Verlet lists): each particle's neighbours within kCut sigmaCap plus a skin, in
/// index order, from a k-d tree over the positions at the last build. A particle that has moved
/// more than half the skin since then is "fast": its neighbours come from a search around its
/// position in that tree, and every particle finds the fast ones in a small tree over their
/// current positions. Any pair within kCut sigmaCap is found (a pair of slow particles moved less
/// than the skin together), so the forces are those of a full search per iteration, summed in
/// the same index order, bit for bit. The lists are rebuilt when more than 1/20 of the
/// particles are fast and when particles are born or die. The searches and their sort were 45 % of the time (perf, 20,000 roots on head_max4);
/// a few particles that keep jumping (thin or folded parts of a band) made a global skin test
/// rebuild every iteration on woman_head and ruby_head.
struct Relaxation
{
    explicit Relaxation(const FollicleRun& run)
        : alpha(run.params.alpha), eHat(run.params.energyRatio * run.params.alpha), moveScale(run.params.stepScale / (2.0 * alpha)),
          sigmaCap(run.params.fissionRatio * run.sigmaHat), skin(0.5 * run.d), next(run.count), nextSig(run.count), moved(run.count, 0.0),
          fixedGap(run.count, std::numeric_limits<double>::max())
    {
    }

    const double alpha, eHat;
    const double moveScale;  ///< uniform radii: stepScale sigma^2 grad E
    /// Interactions use radii of at most sigmaCap (the fission threshold), so the neighbour lists
    /// have one radius for the whole run: a particle beyond it splits at its next control step,
    /// and one that cannot (alone on a scrap of surface too small for two) would otherwise widen
    /// every particle's search.
    const double sigmaCap;
    const double skin;
    std::vector<Vec3d> next;
    std::vector<double> nextSig, moved, fixedGap;  ///< fixedGap: squared distance to the nearest contour particle
    // Neighbour lists.
    std::vector<std::vector<std::uint32_t>> lists;
    std::vector<Vec3d> builtAt, fastPos;
    std::vector<std::uint32_t> fastIds;
    std::vector<char> fast;
    std::size_t fastCount = 0;
    const PointCloud builtCloud{&builtAt}, fastCloud{&fastPos};
    std::unique_ptr<PointKdTree> builtTree, fastTree;
};

/// Every particle's neighbour list, from a new k-d tree over the positions now.
void buildLists(const FollicleRun& run, Relaxation& rx)
{
    const std::vector<Vec3d>& pos = run.pos;
    rx.builtAt = pos;
    rx.lists.assign(run.count, {});
    const double listR = kCut * rx.sigmaCap + rx.skin;
    rx.builtTree = std::make_unique<PointKdTree>(3, rx.builtCloud, nanoflann::KDTreeSingleIndexAdaptorParams(16));
    forRange(run.count, run.threaded, [&](const tbb::blocked_range<std::size_t>& r) {
        std::vector<std::pair<std::uint32_t, double>> nb;
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
            nb.clear();
            rx.builtTree->radiusSearch(pos[i].asPointer(), listR * listR, nb, nanoflann::SearchParams(32, 0.f, false));
            std::vector<std::uint32_t>& list = rx.lists[i];
            for (const auto& m : nb) if (m.first != i) list.push_back(m.first);
            std::sort(list.begin(), list.end());
        }
    });
}

/// The fast particles of this iteration and their tree; the lists rebuilt instead when there are
/// too many or the particles changed.
void updateNeighbours(const FollicleRun& run, Relaxation& rx)
{
    const std::size_t count = run.count;
    const std::vector<Vec3d>& pos = run.pos;
    std::size_t& fastCount = rx.fastCount;
    fastCount = 0;
    rx.fast.assign(count, 0);
    if (rx.builtAt.size() == count) {
        for (std::size_t i = 0; i < count; ++i) {
            rx.fast[i] = (pos[i] - rx.builtAt[i]).length() > 0.5 * rx.skin;
            fastCount += std::size_t(rx.fast[i]);
        }
    }
    if (rx.builtAt.size() != count || fastCount > count / 20) {
        buildLists(run, rx);
        std::fill(rx.fast.begin(), rx.fast.end(), 0);
        fastCount = 0;
    }
    rx.fastIds.clear();
    rx.fastPos.clear();
    for (std::size_t i = 0; i < count && fastCount > 0; ++i) {
        if (rx.fast[i]) {
            rx.fastIds.push_back(std::uint32_t(i));
            rx.fastPos.push_back(pos[i]);
        }
    }
    rx.fastTree.reset();
    if (fastCount > 0) rx.fastTree = std::make_unique<PointKdTree>(3, rx.fastCloud, nanoflann::KDTreeSingleIndexAdaptorParams(16));
}

/// Free particle @a i's neighbours within kCut sigmaCap, or more, in index order: its list, or,
/// when some particles are fast, its slow neighbours and the fast ones gathered in @a found
/// (@a nb: scratch space).
const std::vector<std::uint32_t>& neighboursOf(const FollicleRun& run, const Relaxation& rx, std::size_t i,
                                                std::vector<std::pair<std::uint32_t, double>>& nb, std::vector<std::uint32_t>& found)
{
    if (rx.fastCount == 0) return rx.lists[i];
    const std::vector<Vec3d>& pos = run.pos;
    const double searchR2 = (kCut * rx.sigmaCap) * (kCut * rx.sigmaCap), fastR = kCut * rx.sigmaCap + 0.5 * rx.skin;
    found.clear();
    if (!rx.fast[i]) {
        for (const std::uint32_t j : rx.lists[i]) if (!rx.fast[j]) found.push_back(j);
    } else {
        nb.clear();
        rx.builtTree->radiusSearch(pos[i].asPointer(), fastR * fastR, nb, nanoflann::SearchParams(32, 0.f, false));
        for (const auto& m : nb) if (m.first != i && !rx.fast[m.first]) found.push_back(m.first);
    }
    nb.clear();
    rx.fastTree->radiusSearch(pos[i].asPointer(), searchR2, nb, nanoflann::SearchParams(32, 0.f, false));
    for (const auto& m : nb) if (rx.fastIds[m.first] != i) found.push_back(rx.fastIds[m.first]);
    if (rx.fast[i] || !nb.empty()) std::sort(found.begin(), found.end());
    return found;
}

/// One iteration's move and new radius of free particle @a i among its @a candidates, into the
/// relaxation's next positions and radii.
void moveParticle(const FollicleRun& run, Relaxation& rx, ScalpSampler::Local& local, std::size_t i, const std::vector<std::uint32_t>& candidates)
{
    const std::vector<Vec3d>& pos = run.pos;
    const std::vector<double>& sig = run.sig;
    const FollicleParams& params = run.params;
    const std::size_t fixedCount = run.fixedCount;
    const double alpha = rx.alpha, sigmaCap = rx.sigmaCap, h = run.h, clearance2 = run.clearance2;
    // Witkin & Heckbert: E_i = sum_j alpha exp(-r^2 / 2 sigma_i^2) (cut at kCut sigma_i),
    // the move sigma_i^2 sum_j r_ij (E_ij / sigma_i^2 + E_ji / sigma_j^2), and
    // dE_i / dsigma_i for the radius feedback.
    const double si = std::min(sig[i], sigmaCap), si2 = si * si;
    Vec3d force(0.0);
    double energy = 0.0, dEnergy = 0.0;
    for (const std::uint32_t j : candidates) {
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
    Vec3d f = force * rx.moveScale;
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
    for (const std::uint32_t j : candidates) {
        if (j >= fixedCount) break;  // index order: the fixed come first
        nearFixed = std::min(nearFixed, (pos[i] - pos[j]).lengthSqr());
    }
    rx.fixedGap[i] = nearFixed;
    auto clearOfContour = [&](const Vec3d& q) {
        if (nearFixed >= clearance2 * 16.0) return true;
        double m = std::numeric_limits<double>::max();
        for (const std::uint32_t j : candidates) {
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
    rx.next[i] = p;
    rx.moved[i] = (p - pos[i]).length();
    // Radius feedback: dsigma/dt = -rho (E_i - E_hat) / (dE_i/dsigma_i + beta / sigma_hat).
    double ds = params.radiusStep * -params.feedback * (energy - rx.eHat) / (dEnergy + params.beta / run.sigmaHat);
    ds = std::clamp(ds, -0.1 * si, 0.1 * si);
    rx.nextSig[i] = std::clamp(sig[i] + ds, kMinRadius * run.sigmaHat, kMaxRadius * run.sigmaHat);
}

/// Step 5, relaxation: Witkin-Heckbert repulsion and radius feedback, all particles at once, with
/// fission and death every controlInterval iterations.
void relax(FollicleRun& run, Follicles& out)
{
    const FollicleParams& params = run.params;
    const double d = run.d;
    Relaxation rx(run);
    ProgressCounter progress(run.interrupter, "relaxing roots", std::uint64_t(params.maxIterations), "iterations");
    int it = 0;
    std::size_t lastControlChange = 0;
    for (; it < params.maxIterations; ++it) {
        updateNeighbours(run, rx);
        forRange(run.count, run.threaded, [&](const tbb::blocked_range<std::size_t>& r) {
            ScalpSampler::Local local(run.sampler);
            std::vector<std::pair<std::uint32_t, double>> nb;
            std::vector<std::uint32_t> found;
            for (std::size_t i = r.begin(); i != r.end(); ++i) {
                if (i < run.fixedCount) {
                    rx.next[i] = run.pos[i];
                    rx.nextSig[i] = run.sig[i];
                    rx.moved[i] = 0.0;
                    continue;
                }
                moveParticle(run, rx, local, i, neighboursOf(run, rx, i, nb, found));
            }
        });
        run.pos.swap(rx.next);
        run.sig.swap(rx.nextSig);
        double worst = 0.0;
        for (double m : rx.moved) worst = std::max(worst, m);
        out.lastMove = worst / d;
        if (progress.add(1)) throw InterruptedError(run.where + ": interrupted");
        const bool settled = worst < params.tolerance * d;
        // Fission and death (populationControl), not in the last settleIterations.
        const bool mayControl = params.controlInterval > 0 && it + 1 + params.settleIterations <= params.maxIterations;
        if (mayControl && (settled || (it + 1) % params.controlInterval == 0)) {
            const PopulationChange change = populationControl(run.sampler, params, it, run.targetCount, run.fixedCount, run.sigmaHat, rx.moved, rx.fixedGap,
                                                              run.clearance2, run.pos, run.sig, run.ids, run.nextId);
            out.fissions += change.fissions;
            out.deaths += change.deaths;
            if (change.fissions + change.deaths > 0) {
                const std::size_t count = run.count = run.pos.size();
                rx.next.resize(count);
                rx.nextSig.resize(count);
                rx.moved.assign(count, 0.0);
                rx.fixedGap.assign(count, std::numeric_limits<double>::max());
                rx.builtAt.clear();  // rebuild the lists
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
    if (run.count > run.fixedCount) {
        const auto [lo, hi] = std::minmax_element(run.sig.begin() + std::ptrdiff_t(run.fixedCount), run.sig.end());
        out.radiusSpread = (*hi - *lo) / run.sigmaHat;
    }
}

/// Step 6, death: a particle within 0.1 d of an earlier one is removed (they have no force between
/// them once they coincide, which projection onto thin or folded parts of a band can cause).
void removeCoincident(FollicleRun& run, Follicles& out)
{
    std::vector<Vec3d>& pos = run.pos;
    const std::size_t count = run.count;
    const PointCloud cloud{&pos};
    const PointKdTree tree(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(16));
    std::vector<char> alive(count, 1);
    std::vector<std::pair<std::uint32_t, double>> nb;
    const double r2 = (0.1 * run.d) * (0.1 * run.d);
    for (std::size_t i = run.fixedCount; i < count; ++i) {
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
    run.count = k;
}

/// Step 7, frames: each root's position, the surface normal there and a tangent toward @a up.
void rootFrames(const FollicleRun& run, Follicles& out)
{
    const std::size_t count = run.count;
    const std::vector<Vec3d>& pos = run.pos;
    out.positions.resize(count);
    out.normals.resize(count);
    out.tangents.resize(count);
    const Vec3d up = run.params.up.length() > 0.0 ? run.params.up / run.params.up.length() : Vec3d(0, 1, 0);
    forRange(count, run.threaded, [&](const tbb::blocked_range<std::size_t>& r) {
        ScalpSampler::Local local(run.sampler);
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
            const Vec3d n = local.normal(pos[i]);
            out.positions[i] = Vec3f(pos[i]);
            out.normals[i] = Vec3f(n);
            out.tangents[i] = Vec3f(tangentFrom(n, up));
        }
    });
}
} // namespace

ScalpArea measureScalpArea(const openvdb::FloatGrid::ConstPtr& surface, const openvdb::BoolGrid::ConstPtr& region)
{
    return surfaceCells(*surface, ScalpSampler(surface, region), nullptr);
}

const ParamTable<FollicleParams>& follicleParameters()
{
    using P = FollicleParams;
    static const ParamTable<P> table = [] {
        ParamTable<P> t;
        auto count = makeParam<P>("count", "Number of roots", "", member<P>([](P& p) -> std::size_t& { return p.count; }));
        count.min = 0;
        count.zeroMeans = "set by the spacing (give one of the two)";
        count.pythonNone = true;
        t.push_back(count);
        auto spacing = makeParam<P>("spacing", "Target nearest-neighbour spacing, instead of a count", "world units",
                                    member<P>([](P& p) -> double& { return p.spacing; }));
        spacing.min = 0.0;
        spacing.zeroMeans = "set by the count";
        spacing.pythonNone = true;
        t.push_back(spacing);
        t.push_back(makeParam<P>("seed", "Random seed of the initial placement", "", member<P>([](P& p) -> std::uint64_t& { return p.seed; })));
        auto iterations = makeParam<P>("iterations", "Most relaxation iterations", "", member<P>([](P& p) -> int& { return p.maxIterations; }));
        iterations.min = 0;
        t.push_back(iterations);
        auto step = makeParam<P>("step-scale", "Relaxation step as a multiple of sigma^2 times the energy gradient (above about 1 it oscillates)", "",
                                 member<P>([](P& p) -> double& { return p.stepScale; }));
        step.min = 0.0;
        step.aboveMin = true;
        t.push_back(step);
        t.push_back(makeParam<P>("contour", "Fixed roots on the region's rim, lining the hairline", "", member<P>([](P& p) -> bool& { return p.contour; })));
        auto initial = makeParam<P>("initial-fraction", "Share of the roots placed at the start; fission and death make the count", "",
                                    member<P>([](P& p) -> double& { return p.initialFraction; }));
        initial.min = 0.0;
        initial.aboveMin = true;
        initial.max = 4.0;
        t.push_back(initial);
        t.push_back(makeAxisParam<P>("up", "Reference axis of the tangent frame", [](P& p) -> Vec3d& { return p.up; }));
        return t;
    }();
    return table;
}

Follicles sampleFollicles(const openvdb::FloatGrid::ConstPtr& surface, const openvdb::BoolGrid::ConstPtr& region,
                          const FollicleParams& params, bool threaded, openvdb::util::NullInterrupter* interrupter)
{
    const std::string where = "sampleFollicles";
    checkFollicleParams(params, where);
    const ScalpSampler sampler(surface, region);

    // 1. Area of the surface in the region, and the band voxels to draw from (surfaceCells).
    std::vector<SurfaceCell> cells;
    const ScalpArea measured = surfaceCells(*surface, sampler, &cells);
    const double area = measured.area, areaWithoutZero = measured.areaWithoutZero;
    if (cells.empty() || !(area > 0.0)) {
        throw LookupError(where + ": the " + std::string(region ? "region holds" : "surface has") + " no voxel of the zero level set" +
                          (areaWithoutZero > 0.0 ? " (its band never changes sign: an open or unsigned surface)" : "") + "; there is nowhere to put roots");
    }

    // 2. Target count and spacing (targetCount).
    double d = 0.0;
    const std::size_t count = targetCount(params, area, where, d);
    FollicleRun run(*surface, sampler, params, threaded, interrupter, where, d, count);
    Follicles out;
    out.area = area;
    out.areaWithoutZero = areaWithoutZero;
    out.targetSpacing = d;

    // 3. Fixed particles on the region's contour, at the relaxed spacing (contourParticles).
    if (region && params.contour) run.pos = contourParticles(*surface, sampler, cells, kRelaxedNearestPerSpacing * d, threaded, interrupter);
    run.fixedCount = run.pos.size();
    run.clearance2 = std::pow(kContourClearance * kRelaxedNearestPerSpacing * d, 2);
    out.contour = run.fixedCount;

    placeInitialParticles(run, cells, out);  // 4
    relax(run, out);                         // 5
    removeCoincident(run, out);              // 6
    rootFrames(run, out);                    // 7
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
