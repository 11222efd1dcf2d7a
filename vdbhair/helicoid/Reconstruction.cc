#include "Reconstruction.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/Format.h>
#include <vdbhair/Quantile.h>
#include <vdbhair/Random.h>
#include <vdbhair/field/HairVolume.h>
#include <vdbhair/field/HeadCollision.h>
#include <vdbhair/field/TangentField.h>
#include <vdbhair/helicoid/Frechet.h>
#include <vdbhair/helicoid/Scene.h>
#include <vdbhair/helicoid/ShepardWeights.h>
#include <vdbhair/strands/Measures.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <numeric>
#include <utility>

namespace vdbhair {

namespace {

Vec3d toD(const Vec3f& v) { return Vec3d(v.x(), v.y(), v.z()); }

double seconds(std::chrono::steady_clock::time_point t0)
{
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// The strands @a idx of @a s, in that order.
StrandSet subset(const StrandSet& s, const std::vector<std::size_t>& idx)
{
    StrandSet out;
    out.offsets.assign(1, 0);
    for (std::size_t i : idx) {
        out.positions.insert(out.positions.end(), s.positions.begin() + std::ptrdiff_t(s.begin(i)),
                             s.positions.begin() + std::ptrdiff_t(s.begin(i) + s.size(i)));
        out.offsets.push_back(std::uint32_t(out.positions.size()));
    }
    return out;
}

void summarize(ReconstructErrors& e, const std::vector<char>& isGuide)
{
    std::vector<double> all = e.relative, interp;
    for (std::size_t i = 0; i < all.size(); ++i) if (!isGuide[i]) interp.push_back(all[i]);
    auto stats = [](std::vector<double> v, double& mean, double& p95) {
        mean = p95 = 0.0;
        if (v.empty()) return;
        double sum = 0.0;
        for (double x : v) sum += x;  // in strand order: independent of threads
        mean = sum / double(v.size());
        p95 = nearestRankQuantile(std::move(v), 0.95);
    };
    stats(std::move(all), e.mean, e.p95);
    stats(std::move(interp), e.meanInterpolated, e.p95Interpolated);
}

/// The parameters reconstructHairstyle() checks itself (the rest are checked where they are used).
void checkParams(const ReconstructParams& params)
{
    validateShepardParams(params.helicoid.shepard);
    if (!(params.metersPerUnit >= 0.0) || !std::isfinite(params.metersPerUnit)) {
        throw ParamError<ValueError>({paramName(reconstructParameters(), "meters-per-unit"),
                                      " " + formatNumber(params.metersPerUnit) + ": must be a positive length in metres, or 0 for unknown"});
    }
    if (params.points.neighbors < 1) throw ValueError("neighbors " + std::to_string(params.points.neighbors) + ": must be at least 1");
}

/// Fit the selected guides (§5.2-5.3) into a scene of the fitted ones (res.guides; the others
/// count as unfitted), and each fitted guide's step into @a fitStep.
Scene fitGuides(const StrandSet& strands, const std::vector<std::size_t>& selected, const ReconstructParams& params, bool threaded,
                openvdb::util::NullInterrupter* interrupter, std::chrono::steady_clock::time_point t0, ReconstructResult& res,
                std::vector<double>& fitStep)
{
    const StrandSet guideStrands = subset(strands, selected);
    std::vector<std::string> fitErrors;
    const std::vector<StrandFit> fits = fitStrands(guideStrands, params.fit, threaded, &fitErrors, interrupter);
    res.fitSeconds = seconds(t0);
    res.fitSummary = summarizeFits(guideStrands, fits, fitErrors, params.fit.maxError);
    Scene scene;
    scene.integrator = HelicoidIntegrator::RK4;  // fits are streamlines (as `vdbhair fit` writes them)
    std::vector<std::size_t> fittedGuides;
    for (std::size_t g = 0; g < fits.size(); ++g) {
        if (!fitErrors[g].empty()) {
            ++res.unfitted;
            continue;
        }
        scene.guides.push_back(guideFromFit(fits[g]));
        fittedGuides.push_back(selected[g]);
        fitStep[selected[g]] = fits[g].step;
    }
    if (scene.guides.empty()) throw ValueError("no guide strand could be fitted (all have zero length)");
    scene.step = scene.guides.front().step;
    res.guides = fittedGuides;
    return scene;
}

/// #S strands: guides from @a guideSet (in guide order), the others from @a interp.
StrandSet assemble(const std::vector<char>& isGuide, const StrandSet& guideSet, const StrandSet& interp)
{
    StrandSet out;
    out.offsets.assign(1, 0);
    std::size_t g = 0, o = 0;
    for (std::size_t i = 0; i < isGuide.size(); ++i) {
        const StrandSet& src = isGuide[i] ? guideSet : interp;
        const std::size_t k = isGuide[i] ? g++ : o++;
        out.positions.insert(out.positions.end(), src.positions.begin() + std::ptrdiff_t(src.begin(k)),
                             src.positions.begin() + std::ptrdiff_t(src.begin(k) + src.size(k)));
        out.offsets.push_back(std::uint32_t(out.positions.size()));
    }
    return out;
}

/// The baseline: each other strand the nearest guide, translated to its root (@a roots: the
/// others' roots in strand order); guides as they are.
StrandSet nearestGuideBaseline(const StrandSet& strands, const StrandSet& rawGuides, const std::vector<char>& isGuide,
                               const InterpolationRoots& roots)
{
    std::vector<Vec3d> guideRoots;
    for (std::size_t g = 0; g < rawGuides.numStrands(); ++g) guideRoots.push_back(toD(rawGuides.root(g)));
    const GuideLocator locator(guideRoots);
    StrandSet nearest;
    nearest.offsets.assign(1, 0);
    std::size_t o = 0;
    for (std::size_t i = 0; i < strands.numStrands(); ++i) {
        const std::size_t g = isGuide[i] ? std::size_t(-1) : locator.nearest(roots.positions[o++]);
        const StrandSet& src = isGuide[i] ? strands : rawGuides;
        const std::size_t k = isGuide[i] ? i : g;
        const Vec3f shift = isGuide[i] ? Vec3f(0.f) : strands.root(i) - rawGuides.root(g);
        for (std::size_t v = 0; v < src.size(k); ++v) nearest.positions.push_back(src.positions[src.begin(k) + v] + shift);
        nearest.offsets.push_back(std::uint32_t(nearest.positions.size()));
    }
    return nearest;
}

/// Every strand's relative Fréchet error, each way, at the fits' spacing (a guide's own fit's
/// step, else the fit step asked for, else a quarter of the strand's mean edge), then their
/// summaries.
void measureRelativeErrors(const StrandSet& strands, ReconstructResult& res, const StrandSet& nearest, const std::vector<double>& fitStep,
                           const std::vector<char>& isGuide, double fitStepParam, bool threaded)
{
    const std::size_t S = strands.numStrands();
    res.helicoidErrors.relative.assign(S, 0.0);
    res.pointErrors.relative.assign(S, 0.0);
    res.nearestErrors.relative.assign(S, 0.0);
    auto measure = [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
            const std::size_t n = strands.size(i);
            const Vec3f* a = strands.positions.data() + strands.begin(i);
            const double length = polylineLength(a, n);
            double spacing = fitStep[i] > 0.0      ? fitStep[i]
                             : fitStepParam > 0.0 ? fitStepParam
                                                     : 0.25 * length / double(std::max<std::size_t>(1, n - 1));
            if (!(spacing > 0.0)) spacing = 1.0;
            res.helicoidErrors.relative[i] = relativeFrechet(a, n, res.helicoid.positions.data() + res.helicoid.begin(i), res.helicoid.size(i), spacing);
            res.pointErrors.relative[i] = relativeFrechet(a, n, res.points.positions.data() + res.points.begin(i), res.points.size(i), spacing);
            res.nearestErrors.relative[i] = relativeFrechet(a, n, nearest.positions.data() + nearest.begin(i), nearest.size(i), spacing);
        }
    };
    if (threaded) tbb::parallel_for(tbb::blocked_range<std::size_t>(0, S, 16), measure);
    else measure(tbb::blocked_range<std::size_t>(0, S));
    summarize(res.helicoidErrors, isGuide);
    summarize(res.pointErrors, isGuide);
    summarize(res.nearestErrors, isGuide);
}

/// The three reconstructions with the errors they are measured into.
using Ways = std::array<std::pair<ReconstructErrors*, const StrandSet*>, 3>;

/// As hair papers measure (Compare.h): HairGS's oriented points (with a known unit) and Perm's
/// strand-pair errors.
void measureAsPapers(const StrandSet& strands, const Ways& ways, double metersPerUnit, bool threaded)
{
    std::vector<OrientedThreshold> thresholds;
    if (metersPerUnit > 0.0) {
        thresholds = hairGsThresholds();
        for (OrientedThreshold& t : thresholds) t.distance /= metersPerUnit;
    }
    for (const auto& way : ways) {
        if (!thresholds.empty()) way.first->oriented = matchOrientedPoints(*way.second, strands, thresholds, false, threaded);
        const StrandPairErrors perm = strandPairErrors(strands, *way.second, 100, threaded);
        way.first->permPosition = perm.meanPosition;
        way.first->permCurvature = perm.meanCurvature;
    }
}

/// Spikes, flares and the head: the interpolated strands (@a others) against the guides' hair
/// volume, and the original strands at the same roots for comparison.
void measureVolumeAndHead(const StrandSet& strands, const StrandSet& rawGuides, const std::vector<std::size_t>& others, const Ways& ways,
                          const HeadObstacle* head, bool threaded, ReconstructResult& res)
{
    std::vector<char> interpolated(strands.numStrands(), 0);
    for (std::size_t i : others) interpolated[i] = 1;
    res.volumeVoxel = suggestVoxelSize(rawGuides);
    const double n = double(others.size());
    const bool withHead = head && !head->unset() && !head->empty();
    res.headMeasured = withHead;
    const double tolerance = withHead ? headTolerance(*head) : 0.0;
    auto shares = [&](const StrandSet& set, double& leaving, double& entering) {
        const StrandSet sub = selectStrands(set, interpolated);
        leaving = double(countStrandsLeavingVolume(sub, rawGuides, res.volumeVoxel, threaded)) / n;
        entering = withHead ? double(countStrandsEnteringHead(sub, *head, tolerance, threaded)) / n : 0.0;
    };
    shares(strands, res.originalLeavingVolume, res.originalEnteringHead);
    for (const auto& way : ways) shares(*way.second, way.first->leavingVolume, way.first->enteringHead);
}

} // namespace

const char* guideSelectionName(GuideSelection selection) { return selection == GuideSelection::Cluster ? "cluster" : "random"; }

GuideSelection guideSelectionFromName(const std::string& name)
{
    if (name == "random") return GuideSelection::Random;
    if (name == "cluster") return GuideSelection::Cluster;
    throw ValueError("select '" + name + "' is not one of random, cluster");
}

const ParamTable<ReconstructParams>& reconstructParameters()
{
    using P = ReconstructParams;
    static const ParamTable<P> table = [] {
        ParamTable<P> t;
        auto add = [&](Param<P> p) { t.push_back(std::move(p)); };
        auto guides = makeParam<P>("guides", "Share of the strands used as guides, a fraction (the command line's --guides takes a percentage: 10%)", "",
                                   member<P>([](P& p) -> double& { return p.guideFraction; }));
        guides.min = 0.0;
        guides.aboveMin = true;
        guides.max = 1.0;
        add(guides);
        auto select = makeParam<P>("select", "Guide choice: random (a seeded shuffle) or cluster (k-means of the roots: guides spread evenly)", "",
                                   named<P>([](P& p) -> GuideSelection& { return p.selection; }, guideSelectionName, guideSelectionFromName));
        select.choices = {"random", "cluster"};
        add(select);
        add(makeParam<P>("seed", "Seed of the guide choice", "", member<P>([](P& p) -> std::uint64_t& { return p.seed; })));
        for (Param<P>& q : nestedParams<P>(helicoidInterpolationParameters(), [](P& p) -> HelicoidInterpolationParams& { return p.helicoid; })) add(std::move(q));
        add(guideNeighborsParam<P>());
        for (Param<P>& q : nestedParams<P>(pointInterpolationParameters(), [](P& p) -> PointInterpolationParams& { return p.points; })) add(std::move(q));
        for (Param<P>& q : nestedParams<P>(fitParameters(), [](P& p) -> FitParams& { return p.fit; }, {"max-error"})) add(std::move(q));
        auto unit = makeParam<P>("meters-per-unit", "The strands' unit in metres (0.01: centimetres), for HairGS's oriented-point F1 at 2-4 mm", "",
                                 member<P>([](P& p) -> double& { return p.metersPerUnit; }));
        unit.min = 0.0;
        unit.zeroMeans = "unknown, not measured";
        add(unit);
        return t;
    }();
    return table;
}

std::vector<std::size_t> selectGuides(const StrandSet& strands, double fraction, GuideSelection selection, std::uint64_t seed)
{
    const std::size_t S = strands.numStrands();
    if (S == 0) throw ValueError("no strands to select guides from");
    if (!(fraction > 0.0 && fraction <= 1.0)) {
        throw ValueError("guides " + formatNumber(fraction * 100.0) + " %: must be more than 0 % and at most 100 % of the strands");
    }
    const std::size_t G = std::min(S, std::max<std::size_t>(1, std::size_t(std::llround(fraction * double(S)))));
    // A seeded shuffle (Fisher-Yates): the random order.
    std::vector<std::size_t> order(S);
    std::iota(order.begin(), order.end(), 0);
    Rng rng(seed, 0x67756964ull);
    for (std::size_t i = 0; i + 1 < S; ++i) {
        const std::size_t j = i + std::size_t(rng.uniform() * double(S - i));
        std::swap(order[i], order[std::min(j, S - 1)]);
    }
    std::vector<std::size_t> chosen(order.begin(), order.begin() + std::ptrdiff_t(G));
    if (selection == GuideSelection::Cluster && G < S) {
        std::vector<Vec3d> roots(S), centres(G);
        for (std::size_t i = 0; i < S; ++i) roots[i] = toD(strands.root(i));
        for (std::size_t c = 0; c < G; ++c) centres[c] = roots[chosen[c]];
        std::vector<std::uint32_t> label(S);
        for (int it = 0; it < 8; ++it) {
            const GuideLocator loc(centres);
            tbb::parallel_for(tbb::blocked_range<std::size_t>(0, S, 1024), [&](const tbb::blocked_range<std::size_t>& r) {
                for (std::size_t i = r.begin(); i != r.end(); ++i) label[i] = loc.nearest(roots[i]);
            });
            std::vector<Vec3d> sum(G, Vec3d(0.0));
            std::vector<std::size_t> count(G, 0);
            for (std::size_t i = 0; i < S; ++i) {
                sum[label[i]] += roots[i];
                ++count[label[i]];
            }
            for (std::size_t c = 0; c < G; ++c) if (count[c]) centres[c] = sum[c] / double(count[c]);
        }
        std::vector<std::size_t> best(G, S);
        std::vector<double> bestD(G, 0.0);
        for (std::size_t i = 0; i < S; ++i) {
            const std::uint32_t c = label[i];
            const double d = (roots[i] - centres[c]).lengthSqr();
            if (best[c] == S || d < bestD[c]) {
                best[c] = i;
                bestD[c] = d;
            }
        }
        std::vector<char> taken(S, 0);
        chosen.clear();
        for (std::size_t c = 0; c < G; ++c) if (best[c] < S && !taken[best[c]]) { chosen.push_back(best[c]); taken[best[c]] = 1; }
        for (std::size_t i = 0; chosen.size() < G && i < S; ++i) if (!taken[order[i]]) { chosen.push_back(order[i]); taken[order[i]] = 1; }
    }
    std::sort(chosen.begin(), chosen.end());
    return chosen;
}

double relativeFrechet(const Vec3f* a, std::size_t na, const Vec3f* b, std::size_t nb, double spacing)
{
    const double length = polylineLength(a, na);
    if (!(length > 0.0)) return 0.0;
    std::vector<Vec3d> pa(na), pb(nb), da, db;
    for (std::size_t i = 0; i < na; ++i) pa[i] = toD(a[i]);
    for (std::size_t i = 0; i < nb; ++i) pb[i] = toD(b[i]);
    densifyPolyline(pa, 0, na - 1, spacing, da);
    // A reconstruction already at the spacing (a trace, stored in floats: its chords are a
    // rounding longer than its step) is taken as it is; splitting every segment would change the
    // discrete measure. Others are densified exactly as the original.
    double longest = 0.0;
    for (std::size_t i = 0; i + 1 < nb; ++i) longest = std::max(longest, (pb[i + 1] - pb[i]).length());
    if (longest <= spacing * (1.0 + 1e-4)) db = pb;
    else densifyPolyline(pb, 0, nb - 1, spacing, db);
    return discreteFrechet(da.data(), da.size(), db.data(), db.size()) / length;
}

ReconstructResult reconstructHairstyle(const StrandSet& strands, const ReconstructParams& params, bool threaded,
                                       openvdb::util::NullInterrupter* interrupter, const HeadObstacle* head)
{
    checkParams(params);
    const std::size_t S = strands.numStrands();
    ReconstructResult res;
    const std::vector<std::size_t> selected = selectGuides(strands, params.guideFraction, params.selection, params.seed);

    auto t0 = std::chrono::steady_clock::now();
    std::vector<double> fitStep(S, 0.0);  // a guide's errors are measured at its fit's step
    const Scene scene = fitGuides(strands, selected, params, threaded, interrupter, t0, res, fitStep);
    std::vector<char> isGuide(S, 0);
    for (std::size_t i : res.guides) isGuide[i] = 1;
    std::vector<std::size_t> others;
    InterpolationRoots roots;
    for (std::size_t i = 0; i < S; ++i) {
        if (isGuide[i]) continue;
        others.push_back(i);
        roots.positions.push_back(toD(strands.root(i)));
    }

    // The helicoid way: the fits regrown, interpolated hairs at the other roots.
    const StrandSet grownGuides = growScene(scene, {}, threaded, interrupter);
    StrandSet interpHelicoid, interpPoints;
    if (!others.empty()) {
        GrowOptions grow;
        grow.maxVertices = params.helicoid.maxVertices;
        interpHelicoid = growScene(interpolateHelicoids(scene, roots, params.helicoid, {}, threaded, interrupter), grow, threaded, interrupter);
    }
    res.helicoidErrors.seconds = seconds(t0);
    res.helicoid = assemble(isGuide, grownGuides, interpHelicoid);

    // The points way from the same guides' raw strands.
    t0 = std::chrono::steady_clock::now();
    const StrandSet rawGuides = subset(strands, res.guides);
    if (!others.empty()) interpPoints = interpolatePoints(rawGuides, roots, params.points, {}, threaded, interrupter);
    res.pointErrors.seconds = seconds(t0);
    res.points = assemble(isGuide, rawGuides, interpPoints);

    t0 = std::chrono::steady_clock::now();
    const StrandSet nearest = nearestGuideBaseline(strands, rawGuides, isGuide, roots);
    res.nearestErrors.seconds = seconds(t0);

    measureRelativeErrors(strands, res, nearest, fitStep, isGuide, params.fit.step, threaded);
    const Ways ways = {{{&res.helicoidErrors, &res.helicoid}, {&res.pointErrors, &res.points}, {&res.nearestErrors, &nearest}}};
    measureAsPapers(strands, ways, params.metersPerUnit, threaded);
    if (!others.empty()) measureVolumeAndHead(strands, rawGuides, others, ways, head, threaded, res);
    return res;
}

} // namespace vdbhair
