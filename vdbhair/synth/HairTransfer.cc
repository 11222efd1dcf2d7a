#include "HairTransfer.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/Format.h>
#include <vdbhair/Quantile.h>
#include <vdbhair/strands/Resample.h>
#include <vdbhair/synth/RootScatter.h>

#include <algorithm>
#include <cmath>
#include <string>

namespace vdbhair {

const ParamTable<TransferParams>& transferParameters()
{
    using P = TransferParams;
    static const ParamTable<P> table = [] {
        // synth's, but for the coarsest level's layout and roots, which transfer takes from BASE.
        ParamTable<P> t = nestedParams<P>(synthParameters(), [](P& p) -> SynthParams& { return p.synth; },
                                          {"levels", "seed", "vertices", "threshold", "initial-clusters", "components", "detail", "detail-scale",
                                           "match-balance", "match-candidates", "match-place", "refine-mode", "voxel-size", "refine", "up", "front",
                                           "measure"});
        // Measured against BASE, the hairstyle whose flow the output keeps (measureTransfer()).
        for (Param<P>& q : t)
            if (q.name == "measure") q.help = "Also compare the output with BASE as `vdbhair compare` does (the report's \"compare\"; BASE is the reference)";
        auto smoothing = makeParam<P>("smoothing", "Sigma of the smoothing of DETAILS' coarsest strands, a fraction of their vertices", "",
                                      member<P>([](P& p) -> double& { return p.smoothing; }));
        smoothing.min = 0.0;
        smoothing.max = 1.0;
        smoothing.zeroMeans = "none";
        t.push_back(smoothing);
        t.push_back(makeParam<P>("guides", "BASE's strands are the coarsest level as they are (a few guides); finer roots are spread over their region", "",
                                 member<P>([](P& p) -> bool& { return p.guides; })));
        auto strands = makeParam<P>("strands", "With guides: strands in the output", "", member<P>([](P& p) -> std::size_t& { return p.strands; }));
        strands.min = 0;
        strands.zeroMeans = "DETAILS' strands per coarsest strand, times the guides";
        strands.pythonNone = true;
        t.push_back(strands);
        // On by default: the flag turns it off (--no-smooth-base; --keep-base-detail, its older name).
        auto smoothBase = makeParam<P>("smooth-base", "Smooth BASE's coarsest level as DETAILS' is (the paper does not: BASE's own wisp-level "
                                                      "waves stay, under DETAILS')", "", member<P>([](P& p) -> bool& { return p.smoothBase; }));
        smoothBase.oldFlags = {"--keep-base-detail"};
        t.push_back(smoothBase);
        return t;
    }();
    return table;
}

void TransferParams::validate(const char* where) const
{
    synth.validate(where);
    if (!(smoothing >= 0.0 && smoothing <= 1.0))
        throw ValueError(std::string(where) + ": smoothing " + std::to_string(smoothing) + ": 0 to 1 (a fraction of the strand's vertices)");
    if (!(maxLengthRatio >= 1.0) || !std::isfinite(maxLengthRatio))
        throw ValueError(std::string(where) + ": length ratio " + std::to_string(maxLengthRatio) + ": a finite ratio of at least 1");
}

void smoothSamples(StrandSamples& samples, double fraction, double radius)
{
    const int ns = samples.vertices;
    std::vector<Vec3d> in(static_cast<std::size_t>(ns)), out(static_cast<std::size_t>(ns));
    for (std::size_t s = 0; s < samples.count(); ++s) {
        float* row = samples.row(s);
        for (int l = 0; l < ns; ++l) in[std::size_t(l)] = Vec3d(row[3 * l], row[3 * l + 1], row[3 * l + 2]);
        smoothPolyline(in.data(), in.size(), fraction * double(ns), out.data());
        double len = 0.0;
        for (int l = 0; l < ns; ++l) {
            row[3 * l] = float(out[std::size_t(l)].x());
            row[3 * l + 1] = float(out[std::size_t(l)].y());
            row[3 * l + 2] = float(out[std::size_t(l)].z());
            if (l > 0) len += (out[std::size_t(l)] - out[std::size_t(l - 1)]).length();
        }
        samples.lengths[s] = float(len * radius);
    }
}

namespace {

double medianLength(const StrandSamples& s, double radius)
{
    if (s.lengths.empty()) return 0.0;
    return upperMedian(std::vector<double>(s.lengths.begin(), s.lengths.end())) / radius;
}

/// BASE's coarsest level and the output counts per level, with what the finer levels' roots need.
struct BaseCoarsest
{
    std::vector<std::size_t> counts;      ///< output strands per level
    UvGrid grid;                          ///< guides: the uv grid of the guides' region
    FeatureImage region;                  ///< guides: within two guide spacings of a guide's root
    std::vector<std::uint32_t> baseOrder; ///< not guides: BASE's strands in the order of its hierarchy
};

/// Step 4, the coarsest level: BASE's strands as they are (guides; DETAILS' strands per coarsest
/// strand at every level, scaled to the requested finest count), or BASE's own hierarchy's
/// coarsest level.
BaseCoarsest imposeBaseCoarsest(TransferResult& tr, const StrandSet& base, const TransferParams& params, bool threaded,
                                openvdb::util::NullInterrupter* interrupter)
{
    const SynthParams& sp = params.synth;
    const int L = sp.cluster.levels;
    SynthResult& res = tr.result;
    const ScalpMap& map = *res.map;
    const StrandSamples& detailsCoarsest = res.example.levels.back();
    BaseCoarsest bc;
    bc.counts.assign(std::size_t(L), 0);
    if (params.guides) {
        res.output.back() = sampleStrands(base, map, sp.vertices, threaded);
        const std::vector<Vec3d>& at = res.output.back().scalp;
        bc.grid = uvGridAround(at, sp.mapSpacing);
        const std::vector<float> none(at.size(), 0.0f);
        bc.region = buildFeatureMap(bc.grid, at, none.data(), 1, at, std::max(sp.mapSpacing, 2.0 * medianUvSpacing(at)));
        const double g = double(base.numStrands());
        const double perGuide = double(res.example.levels.front().count()) / double(detailsCoarsest.count());
        const double f = params.strands > 0 ? double(params.strands) / (g * perGuide) : sp.strandScale;
        for (int l = 0; l < L; ++l)
            bc.counts[std::size_t(l)] = std::max<std::size_t>(
                1, std::size_t(std::llround(g * double(res.example.levels[std::size_t(l)].count()) / double(detailsCoarsest.count()) * f)));
        bc.counts.back() = base.numStrands();
    } else {
        try {
            tr.base = hairHierarchy(base, map, sp, threaded, interrupter, &bc.baseOrder);
        } catch (const ValueError& e) {
            throw ValueError(std::string("BASE: ") + e.what());
        }
        res.output.back() = tr.base.levels.back();
        for (int l = 0; l < L; ++l) bc.counts[std::size_t(l)] = tr.base.levels[std::size_t(l)].count();
    }
    return bc;
}

/// Wisps too different in length cannot be matched (HairTransfer.h). Both coarsest levels are
/// smoothed at one scale in head radii (σ = smoothing × BASE's wisp length), and detail laid by
/// arc length onto longer wisps keeps DETAILS' spacing: n_s × the ratio of the smoothed wisps'
/// lengths (the centres along which the detail is laid) vertices, within the caps.
void matchWispLengths(TransferResult& tr, const TransferParams& params, std::size_t finestCount)
{
    const SynthParams& sp = params.synth;
    SynthResult& res = tr.result;
    const double radius = res.map->radius();
    const StrandSamples& detailsCoarsest = res.example.levels.back();
    const double lb = medianLength(res.output.back(), radius), ld = medianLength(detailsCoarsest, radius);
    tr.lengthRatio = ld > 0.0 ? lb / ld : 0.0;
    if (!(tr.lengthRatio <= params.maxLengthRatio && tr.lengthRatio >= 1.0 / params.maxLengthRatio))
        throw ValueError("coarsest wisps of BASE " + formatNumber(lb) + " head radii long (median), of DETAILS " + formatNumber(ld) +
                         ": more than " + formatNumber(params.maxLengthRatio) + " times apart, too different for their clusters to be matched");
    tr.detailsSmoothing = std::min(1.0, params.smoothing * tr.lengthRatio);
    smoothSamples(res.example.levels.back(), tr.detailsSmoothing, radius);
    if (params.smoothBase) smoothSamples(res.output.back(), params.smoothing, radius);
    const double smoothedRatio = medianLength(res.output.back(), radius) / std::max(1e-300, medianLength(detailsCoarsest, radius));
    tr.outputVertices = sp.vertices;
    if (sp.detailScale == DetailScale::ArcLength && smoothedRatio > 1.0)
        tr.outputVertices = int(std::max(double(sp.vertices), std::min({double(kMaxOutputVertices), std::round(double(sp.vertices) * smoothedRatio),
                                                                          std::floor(double(params.outputVertexBudget) / double(finestCount))})));
    if (double(finestCount) * tr.outputVertices > double(sp.maxVertices))
        throw LimitError("transferHairstyle: " + std::to_string(finestCount) + " strands of " + std::to_string(tr.outputVertices) +
                         " vertices exceed the cap of " + std::to_string(sp.maxVertices) + " vertices");
}

/// The roots of finer level @a l: spread over the guides' region (guides), or BASE's roots with
/// BASE's own wisps (each root's centre is its cluster in BASE's hierarchy).
LevelRoots transferLevelRoots(const TransferResult& tr, const BaseCoarsest& bc, const StrandSet& base, const TransferParams& params,
                              int l, bool threaded)
{
    const SynthParams& sp = params.synth;
    LevelRoots out;
    if (params.guides) {
        RootScatterParams rp;
        rp.count = bc.counts[std::size_t(l)];
        rp.iterations = sp.rootIterations;
        rp.seed = sp.seed;
        rp.stream = std::uint64_t(l);
        out.positions = scatterRoots(*tr.result.map, bc.grid, bc.region, rp, threaded).positions;
        return out;
    }
    const std::vector<std::uint32_t>& label = tr.base.clusterings[std::size_t(l)].label;
    if (l == 0) {  // BASE's own strands, in BASE's order
        out.positions.resize(base.numStrands());
        out.parent.resize(base.numStrands());
        for (std::size_t i = 0; i < bc.baseOrder.size(); ++i) {
            out.positions[bc.baseOrder[i]] = Vec3d(base.root(bc.baseOrder[i]));
            out.parent[bc.baseOrder[i]] = label[i];
        }
    } else {
        out.positions = tr.base.levels[std::size_t(l)].roots;
        out.parent = label;
    }
    return out;
}

/// Each BASE strand's coarsest cluster (itself with guides).
std::vector<std::int32_t> baseLabels(const TransferResult& tr, std::size_t baseStrands, bool guides, const std::vector<std::uint32_t>& baseOrder)
{
    std::vector<std::int32_t> label(baseStrands);
    for (std::size_t s = 0; s < baseStrands; ++s) label[s] = std::int32_t(s);
    if (!guides)
        for (std::size_t i = 0; i < baseOrder.size(); ++i) {
            std::uint32_t c = std::uint32_t(i);
            for (const Clustering& cl : tr.base.clusterings) c = cl.label[c];
            label[baseOrder[i]] = std::int32_t(c);
        }
    return label;
}

} // namespace

TransferResult transferHairstyle(const StrandSet& details, const StrandSet& base, const TransferParams& params,
                                 openvdb::FloatGrid::ConstPtr baseScalp, bool threaded,
                                 openvdb::util::NullInterrupter* interrupter)
{
    params.validate("transferHairstyle");
    const SynthParams& sp = params.synth;
    const int L = sp.cluster.levels;
    if (details.numStrands() == 0) throw ValueError("DETAILS has no strands");
    if (base.numStrands() == 0) throw ValueError("BASE has no strands");
    TransferResult tr;
    SynthResult& res = tr.result;
    // 1. Both scalps.
    {
        SynthStageTimer t{res.stages, "scalp"};
        tr.detailsMap = hairScalpMap(details, sp.up, nullptr);
        res.map = hairScalpMap(base, sp.up, baseScalp, &res.up);
    }
    tr.detailScale = res.map->radius() / tr.detailsMap->radius();
    // 2-3. DETAILS' hierarchy in BASE's scale.
    {
        SynthStageTimer t{res.stages, "clustering"};
        try {
            res.example = hairHierarchy(details, *tr.detailsMap, sp, threaded, interrupter);
        } catch (const ValueError& e) {
            throw ValueError(std::string("DETAILS: ") + e.what());
        }
        for (StrandSamples& level : res.example.levels) {
            for (Vec3d& r : level.roots) r *= tr.detailScale;
            for (float& len : level.lengths) len = float(double(len) * tr.detailScale);
        }
    }
    // 4. The coarsest level: BASE's; then its wisps' lengths against DETAILS'.
    res.output.resize(std::size_t(L));
    BaseCoarsest bc;
    {
        SynthStageTimer t{res.stages, "coarsest level"};
        bc = imposeBaseCoarsest(tr, base, params, threaded, interrupter);
    }
    matchWispLengths(tr, params, bc.counts[0]);
    // 5. Finer levels.
    const auto rootsOf = [&](int l) { return transferLevelRoots(tr, bc, base, params, l, threaded); };
    double finestVoxel = sp.voxelSize;
    if (finestVoxel <= 0.0) finestVoxel = params.guides ? suggestVoxelSize(details) * tr.detailScale : suggestVoxelSize(base);
    synthesizeFinerLevels(res, res.example, rootsOf, sp, finestVoxel, /*refineCoarsest=*/false, baseScalp, threaded, interrupter,
                          tr.outputVertices);
    tr.baseLabel = baseLabels(tr, base.numStrands(), params.guides, bc.baseOrder);
    // The head: BASE's (its scalp, else the sphere fitted to its roots), no new vertex deeper than its root.
    keepHairOutOfHead(res, synthesisHead(sp, baseScalp, false, base, res.up), &base, threaded);
    return tr;
}

} // namespace vdbhair
