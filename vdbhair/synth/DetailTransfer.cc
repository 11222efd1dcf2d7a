#include "DetailTransfer.h"

#include <vdbhair/Memory.h>

#include <vdbhair/Exceptions.h>
#include <vdbhair/Format.h>
#include <vdbhair/Quantile.h>
#include <vdbhair/Rotation.h>
#include <vdbhair/strands/Resample.h>
#include <vdbhair/strands/PointCloud.h>
#include <vdbhair/strands/Frames.h>
#include <vdbhair/synth/FeatureMap.h>
#include <vdbhair/synth/Synthesis.h>
#include <vdbhair/synth/impl/BalancedMatch.h>
#include <vdbhair/synth/impl/DetailEdges.h>

#include <vdbhair/Parallel.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <tuple>
#include <utility>

namespace vdbhair {

DetailBlend detailBlendFromName(const std::string& name)
{
    if (name == "root-frame") return DetailBlend::RootFrame;
    if (name == "paper") return DetailBlend::Paper;
    if (name == "edges") return DetailBlend::Edges;
    throw ValueError("detail blend '" + name + "' is not one of edges, root-frame, paper");
}

const char* detailBlendName(DetailBlend blend)
{
    switch (blend) {
    case DetailBlend::Paper: return "paper";
    case DetailBlend::Edges: return "edges";
    default: return "root-frame";
    }
}

DetailScale detailScaleFromName(const std::string& name)
{
    if (name == "index") return DetailScale::Index;
    if (name == "arc-length") return DetailScale::ArcLength;
    if (name == "strand") return DetailScale::Strand;
    throw ValueError("detail scale '" + name + "' is not one of index, arc-length, strand");
}

const char* detailScaleName(DetailScale scale)
{
    switch (scale) {
    case DetailScale::ArcLength: return "arc-length";
    case DetailScale::Strand: return "strand";
    default: return "index";
    }
}

void DetailMatchParams::validate(const char* where) const
{
    if (!(balance == 0.0 || (balance >= 1.0 && std::isfinite(balance))))
        throw ParamError<ValueError>({std::string(where) + ": ", paramName(synthParameters(), "match-balance"),
                                      " " + formatNumber(balance) + ": 0 (off) or a finite factor of at least 1"});
    if (candidates < 1) {
        throw ParamError<ValueError>({std::string(where) + ": ", paramName(synthParameters(), "match-candidates"),
                                      " " + std::to_string(candidates) + ": must be at least 1"});
    }
    if (!(place >= 0.0) || !std::isfinite(place)) {
        throw ParamError<ValueError>({std::string(where) + ": ", paramName(synthParameters(), "match-place"),
                                      " " + formatNumber(place) + ": must be 0 (off) or a positive finite weight"});
    }
}

ScalpFrame alignedFrame(const float* row, int vertices, const ScalpFrame& f)
{
    // v_g in root-frame coordinates (root at 0), projected onto the tangent plane (x, z).
    double x = 0.0, z = 0.0;
    for (int l = 1; l < vertices; ++l) {
        x += row[3 * l];
        z += row[3 * l + 2];
    }
    const double len = std::hypot(x, z);
    if (len < 1e-12) return f;
    const double c = x / len, s = z / len;
    ScalpFrame a;
    a.n = f.n;
    a.t = f.t * c + f.b * s;
    a.b = a.t.cross(a.n);
    return a;
}

namespace {

/// Row @a row of a sample re-expressed in @a to (from its root frame @a from).
void reexpress(const float* row, int vertices, const ScalpFrame& from, const ScalpFrame& to, float* out)
{
    for (int l = 0; l < vertices; ++l) {
        const Vec3d w = from.toWorld(Vec3d(row[3 * l], row[3 * l + 1], row[3 * l + 2]));
        const Vec3d q = to.toLocal(w);
        out[3 * l] = float(q.x());
        out[3 * l + 1] = float(q.y());
        out[3 * l + 2] = float(q.z());
    }
}

/// Row @a row of @a from vertices at @a to vertices, linearly between vertices at the same fraction
/// of the vertices (the samples are even in arc length); a copy when the counts agree.
void resampleRow(const float* row, int from, int to, float* out)
{
    if (from == to) {
        std::copy(row, row + 3 * from, out);
        return;
    }
    for (int k = 0; k < to; ++k) {
        const double x = double(k) * double(from - 1) / double(to - 1);
        const int j = std::min(int(x), from - 1);
        const double t = x - double(j);
        for (int c = 0; c < 3; ++c)
            out[3 * k + c] = j + 1 < from && t > 0.0 ? float(row[3 * j + c] * (1.0 - t) + row[3 * (j + 1) + c] * t) : row[3 * j + c];
    }
}

std::vector<Vec3f> worldOf(const StrandSamples& s, std::size_t i, double radius)
{
    std::vector<Vec3f> p(std::size_t(s.vertices));
    sampleToWorld(s.row(i), s.vertices, s.roots[i], s.frames[i], radius, p.data());
    return p;
}


double polylineLengthOf(const std::vector<Vec3d>& p)
{
    double len = 0.0;
    for (std::size_t k = 1; k < p.size(); ++k) len += (p[k] - p[k - 1]).length();
    return len;
}

/// Carrier smoothing (DetailBlend::Edges), σ as a fraction of a strand's vertices n_s.
/// A laid strand turns as its edges do plus as its output carrier turns against its own carrier,
/// and turning adds up in absolute value: so a carrier that keeps part of the curl gives that part
/// to the output centre's carrier, which replaces it (Curly_100 onto straight.hair kept 6.3-6.8 of
/// its 7.9 turning per head radius with strands and centres both at StrandSamples::kDetailSmoothing
/// of n_s), while an output centre that is itself a laid strand (a level below the coarsest) keeps
/// curl that a centre of the input, a mean of strands, does not have (Curly_100 synthesized came out
/// with about a quarter more turning per strand than the strands it copied). Hence strands' carriers
/// smoother than kDetailSmoothing (more of a strand is detail, carried whole) and centres' much
/// smoother (their curl is not added twice). Chosen from a sweep over seeds 0-6 (strands 1/8 to
/// 1/4, centres 1/8 to 2), with collinear runs (strandEdges()): Curly_100 onto straight.hair
/// 7.32-8.08 turning per head radius, onto harolongo 7.76-8.49 (its own 7.90), synthesized its
/// turning distance 0.04-0.19 (0.08-0.26 at 5/32 without collinear runs); a compromise between
/// the three, not an optimum of any.
constexpr double kStrandCarrierSmoothing = 3.0 / 16.0;
constexpr double kCentreCarrierSmoothing = 0.5;
/// A wisp's curl (wispCurl()) is measured on its strands smoothed at σ = 3/64 of their vertices,
/// about one vertex spacing of a coarse capture (Curly_100's strands have 10-47 vertices), so
/// that a polyline's corners do not count as curl. Curly_100 onto straight.hair, seeds 0-3, curl
/// amplitude, wavelength and turning per head radius against the example's (curl.py's measure,
/// docs/synthesis.md): unsmoothed, the helix came out 15-23 % too short in wavelength and 8-12 %
/// over in turning; at 3/64, within 3 %, 11 % and 3 %; at 6/64 amplitude fell 12 %.
constexpr double kCurlSmoothing = 3.0 / 64.0;

/// One transferDetail() call: its inputs and their sizes, and what each step below leaves for the
/// steps after it.
struct DetailTransferRun
{
    DetailTransferRun(const TransferSource& src, const StrandSamples& centres, const std::vector<Vec3d>& newRoots, const ScalpMap& scalpMap,
                      DetailBlend detailBlend, DetailScale detailScale, int outVertices, const DetailMatchParams& matchParams, bool runThreaded)
        : source(src), inS(*src.strands), inC(*src.centers), outCenters(centres), roots(newRoots), map(scalpMap), blend(detailBlend),
          scale(detailScale), matching(matchParams), threaded(runThreaded), ns(inS.vertices), nc(centres.vertices),
          no(outVertices > 0 ? outVertices : nc), dim(inS.dim()), nIn(inC.count()), nOut(centres.count()), n(newRoots.size()),
          radius(scalpMap.radius()), balanced(matchParams.balance > 0.0), edges(detailBlend == DetailBlend::Edges),
          sigmaCentre(kCentreCarrierSmoothing * double(ns)), sigmaStrand(kStrandCarrierSmoothing * double(ns))
    {
    }

    const TransferSource& source;
    const StrandSamples& inS;         ///< the input's strands
    const StrandSamples& inC;         ///< the input's centres
    const StrandSamples& outCenters;  ///< the coarser output strands
    const std::vector<Vec3d>& roots;  ///< the new strands' roots
    const ScalpMap& map;
    const DetailBlend blend;
    const DetailScale scale;
    const DetailMatchParams& matching;
    const bool threaded;
    const int ns, nc, no;                 ///< vertices of an input strand, of an output centre, of a new strand
    const std::size_t dim, nIn, nOut, n;  ///< floats in an input row; input centres, output centres, new strands
    const double radius;
    const bool balanced, edges;           ///< DetailMatchParams::balance on; DetailBlend::Edges
    const double sigmaCentre, sigmaStrand;  ///< carrier smoothing of centres and of strands, in vertices
    // clusterRoots()
    std::vector<std::uint32_t> label;  ///< #n: each new strand's output centre
    // alignCentres()
    std::vector<ScalpFrame> inAligned, outAligned;
    std::vector<float> rows;  ///< input then output centres in their aligned frames, n_s vertices each
    // matchClusters()
    std::vector<std::uint32_t> match;  ///< #nOut: each output centre's input centre
    // matchStrands()
    std::vector<std::uint32_t> pickOf;  ///< #n: each new strand's input strand
    // centreGeometry()
    std::vector<std::vector<Vec3f>> outWorld, inWorld;
    std::vector<std::vector<Frame>> outRmf, inRmf;
    std::vector<std::uint8_t> inUsed, outUsed;
    // centreCarriers()
    std::vector<double> inCarrierLength;
    std::vector<detail::Carrier> inCarrier, outCarrier;
    std::vector<detail::Curl> inCurl;  ///< DetailScale::ArcLength: each used input centre's wisp's curl
    // readPositions()
    std::vector<std::vector<double>> atOf;  ///< per output centre used, where each output vertex reads

    template<typename BodyT>
    void forEach(std::size_t count, BodyT&& fn) const
    {
        forEachIndex(count, threaded, fn, 64);
    }
};

/// The checks of transferDetail()'s arguments, before any work.
void checkTransferInputs(const TransferSource& source, const StrandSamples& outCenters, int outVertices, const DetailMatchParams& matching)
{
    matching.validate("transferDetail");
    if (!source.strands || !source.centers || !source.label || source.strands->count() == 0 ||
        source.centers->count() == 0 || source.label->size() != source.strands->count())
        throw ValueError("transferDetail: the input level is incomplete or empty");
    if (outCenters.count() == 0) throw ValueError("transferDetail: no coarser output strands to transfer onto");
    const int ns = source.strands->vertices, nc = outCenters.vertices, no = outVertices > 0 ? outVertices : nc;
    if (source.centers->vertices != ns)
        throw ValueError("transferDetail: the input levels have different vertex counts per strand");
    if (ns < 2 || nc < 2 || no < 2) throw ValueError("transferDetail: strands need at least 2 vertices");
}

/// Step 1, output clusters: each new root joins the nearest coarser output root (or its given centre).
void clusterRoots(DetailTransferRun& run, const std::vector<std::uint32_t>* givenLabel)
{
    const std::size_t n = run.n, nOut = run.nOut;
    std::vector<std::uint32_t>& label = run.label;
    label.assign(n, 0);
    if (givenLabel) {
        if (givenLabel->size() != n)
            throw ValueError("transferDetail: " + std::to_string(givenLabel->size()) + " given centres for " + std::to_string(n) + " roots");
        for (std::uint32_t c : *givenLabel)
            if (c >= nOut) throw ValueError("transferDetail: given centre " + std::to_string(c) + " of " + std::to_string(nOut));
        label = *givenLabel;
    } else {
        PointCloud cloud{&run.outCenters.roots};
        PointKdTree tree(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(16));
        tree.buildIndex();
        const std::vector<Vec3d>& roots = run.roots;
        run.forEach(n, [&](std::size_t i) {
            std::uint32_t idx;
            double d2;
            const double q[3] = {roots[i].x(), roots[i].y(), roots[i].z()};
            tree.knnSearch(q, 1, &idx, &d2);
            label[i] = idx;
        });
    }
}

/// Step 2: the aligned frame of every centre and its row in it, input and output centres both at
/// the input's n_s vertices; balanced, each set's rows over its median centre length.
void alignCentres(DetailTransferRun& run)
{
    const StrandSamples& inC = run.inC;
    const StrandSamples& outCenters = run.outCenters;
    const int ns = run.ns, nc = run.nc;
    const std::size_t dim = run.dim, nIn = run.nIn, nOut = run.nOut;
    std::vector<ScalpFrame>& inAligned = run.inAligned;
    std::vector<ScalpFrame>& outAligned = run.outAligned;
    std::vector<float>& rows = run.rows;
    inAligned.resize(nIn);
    outAligned.resize(nOut);
    rows.resize((nIn + nOut) * dim);
    run.forEach(nIn, [&](std::size_t c) {
        inAligned[c] = alignedFrame(inC.row(c), ns, inC.frames[c]);
        reexpress(inC.row(c), ns, inC.frames[c], inAligned[c], rows.data() + c * dim);
    });
    run.forEach(nOut, [&](std::size_t c) {
        // Compared at the input's n_s vertices (the same row when the counts agree).
        std::vector<float> row(dim);
        resampleRow(outCenters.row(c), nc, ns, row.data());
        outAligned[c] = alignedFrame(row.data(), ns, outCenters.frames[c]);
        reexpress(row.data(), ns, outCenters.frames[c], outAligned[c], rows.data() + (nIn + c) * dim);
    });
    if (!run.balanced) return;
    // One scale: each set's rows over its median centre length (DetailMatchParams).
    const auto rowLength = [&](std::size_t r) {
        const float* q = rows.data() + r * dim;
        double len = 0.0;
        for (int l = 1; l < ns; ++l)
            len += std::sqrt(double(q[3 * l] - q[3 * l - 3]) * (q[3 * l] - q[3 * l - 3]) + double(q[3 * l + 1] - q[3 * l - 2]) * (q[3 * l + 1] - q[3 * l - 2]) +
                             double(q[3 * l + 2] - q[3 * l - 1]) * (q[3 * l + 2] - q[3 * l - 1]));
        return len;
    };
    const auto medianOf = [&](std::size_t from, std::size_t count) {
        std::vector<double> v(count);
        for (std::size_t r = 0; r < count; ++r) v[r] = rowLength(from + r);
        return upperMedian(std::move(v));
    };
    const double mIn = medianOf(0, nIn), mOut = medianOf(nIn, nOut);
    for (std::size_t r = 0; r < nIn + nOut; ++r) {
        const double m = r < nIn ? mIn : mOut;
        if (m > 1e-30)
            for (std::size_t k = 0; k < dim; ++k) rows[r * dim + k] = float(rows[r * dim + k] / m);
    }
}

/// DetailMatchParams::place as a factor of squared (u, v) distances: place × the input centres'
/// RMS feature norm per two of their median (u, v) spacings (0 when off or without places).
double matchPlaceScale2(const DetailTransferRun& run, const std::vector<float>& feat, int nf)
{
    const double place = run.matching.place;
    if (!(place > 0.0) || run.inC.scalp.size() != run.nIn || run.outCenters.scalp.size() != run.nOut || run.nIn < 2) return 0.0;
    double sum = 0.0;
    for (std::size_t k = 0; k < run.nIn * std::size_t(nf); ++k) sum += double(feat[k]) * feat[k];
    const double spacing = medianUvSpacing(run.inC.scalp);
    if (!(spacing > 0.0)) return 0.0;
    return place * place * (sum / double(run.nIn)) / (4.0 * spacing * spacing);
}

/// Step 3, matching clusters through PCA features of both sets of centres: each output centre
/// takes the nearest input centre or, balanced, the nearest with room among its candidates.
void matchClusters(DetailTransferRun& run, int components)
{
    const std::size_t dim = run.dim, nIn = run.nIn, nOut = run.nOut, n = run.n;
    const std::vector<float>& rows = run.rows;
    const bool balanced = run.balanced;
    // Each output centre's strands (the load it puts on the input centre it takes).
    std::vector<std::size_t> load(nOut, 0);
    for (std::uint32_t l : run.label) ++load[l];
    const Pca pca = fitPca(rows.data(), nIn + nOut, dim, components);
    const int nf = pca.components;
    std::vector<float> feat((nIn + nOut) * std::size_t(nf));
    run.forEach(nIn + nOut, [&](std::size_t r) { pca.project(rows.data() + r * dim, feat.data() + r * std::size_t(nf)); });
    std::vector<std::uint32_t>& match = run.match;
    match.assign(nOut, 0);
    const std::size_t K = balanced ? std::min<std::size_t>(nIn, std::size_t(run.matching.candidates)) : 1;
    std::vector<std::pair<double, std::uint32_t>> nearest(nOut * K);  // per output centre, its K nearest (distance, input)
    const double placeScale2 = matchPlaceScale2(run, feat, nf);
    run.forEach(nOut, [&](std::size_t c) {
        const float* f = feat.data() + (nIn + c) * std::size_t(nf);
        std::vector<std::pair<double, std::uint32_t>> all(nIn);
        for (std::size_t j = 0; j < nIn; ++j) all[j] = {sampleDistance2(f, feat.data() + j * std::size_t(nf), std::size_t(nf)), std::uint32_t(j)};
        if (placeScale2 > 0.0) {
            const Vec3d& uv = run.outCenters.scalp[c];
            for (std::size_t j = 0; j < nIn; ++j) {
                const Vec3d& in = run.inC.scalp[j];
                all[j].first += placeScale2 * ((uv.x() - in.x()) * (uv.x() - in.x()) + (uv.y() - in.y()) * (uv.y() - in.y()));
            }
        }
        std::partial_sort(all.begin(), all.begin() + std::ptrdiff_t(K), all.end());  // ties to the lower index
        std::copy_n(all.begin(), K, nearest.begin() + std::ptrdiff_t(c * K));
        match[c] = all[0].second;
    });
    if (!balanced) return;
    // Pairs by increasing distance; an input centre serves at most balance × its even share
    // of the output's strands; an output wisp that fits no candidate keeps its nearest.
    std::vector<std::tuple<double, std::uint32_t, std::uint32_t>> pairs;
    for (std::size_t c = 0; c < nOut; ++c)
        if (load[c])
            for (std::size_t k = 0; k < K; ++k) pairs.emplace_back(nearest[c * K + k].first, std::uint32_t(c), nearest[c * K + k].second);
    std::sort(pairs.begin(), pairs.end());
    // An input wisp's share is its own part of the input's strands, so that the output's
    // wisps take detail in the proportions the input has it (and a hairstyle onto itself
    // takes every wisp from itself: an even share turned wisps larger than the mean away
    // from their own detail).
    std::vector<double> share(nIn, 0.0);
    for (std::uint32_t c : *run.source.label) share[c] += run.matching.balance * double(n) / double(run.inS.count());
    std::vector<double> used(nIn, 0.0);
    std::vector<std::uint8_t> done(nOut, 0);
    for (const auto& [d, c, j] : pairs) {
        if (done[c] || used[j] + double(load[c]) > share[j]) continue;
        done[c] = 1;
        used[j] += double(load[c]);
        match[c] = j;
    }
}

/// Step 4, matching strands: each output strand takes a member of its matched input wisp by root
/// offset from the centre (aligned frames). Balanced, pairs are taken by increasing offset
/// distance and a member serves at most balance × its even share of the output wisp's strands
/// (so the output's strands take the input wisp's lengths and curls in its proportions: picked
/// by nearest offset alone, 100 strands of Curly_100 took a few members many times); the
/// paper's rule (balance 0) takes the nearest.
void matchStrands(DetailTransferRun& run)
{
    const StrandSamples& inS = run.inS;
    const StrandSamples& inC = run.inC;
    const StrandSamples& outCenters = run.outCenters;
    const std::vector<Vec3d>& roots = run.roots;
    const std::size_t nIn = run.nIn, nOut = run.nOut, n = run.n;
    const bool balanced = run.balanced;
    // Members of each input cluster.
    std::vector<std::vector<std::uint32_t>> members(nIn);
    for (std::uint32_t s = 0; s < inS.count(); ++s) members[(*run.source.label)[s]].push_back(s);
    std::vector<std::vector<std::uint32_t>> strandsOf(nOut);
    for (std::size_t i = 0; i < n; ++i) strandsOf[run.label[i]].push_back(std::uint32_t(i));
    std::vector<std::uint32_t>& pickOf = run.pickOf;
    pickOf.assign(n, 0);
    run.forEach(nOut, [&](std::size_t oc) {
        const std::vector<std::uint32_t>& mine = strandsOf[oc];
        const std::uint32_t ic = run.match[oc];
        const std::vector<std::uint32_t>& mem = members[ic];
        if (mine.empty() || mem.empty()) return;
        const ScalpFrame& mo = run.outAligned[oc];
        const ScalpFrame& mi = run.inAligned[ic];
        std::vector<Vec3d> offIn(mem.size());
        for (std::size_t k = 0; k < mem.size(); ++k) offIn[k] = mi.toLocal(inS.roots[mem[k]] - inC.roots[ic]);
        // Balanced: the greedy over every (distance², strand, member) pair by increasing distance
        // (impl/BalancedMatch.h; sorting every pair was 5 % of a 100,000-strand synthesis).
        std::vector<detail::MatchCandidate> cand;
        std::vector<std::uint32_t> nearest;
        if (balanced) {
            cand.resize(mine.size() * mem.size());
            nearest.resize(mine.size());
        }
        for (std::size_t a = 0; a < mine.size(); ++a) {
            const Vec3d offOut = mo.toLocal(roots[mine[a]] - outCenters.roots[oc]);
            std::size_t nearestK = 0;
            double best = std::numeric_limits<double>::max();
            detail::MatchCandidate* row = balanced ? cand.data() + a * mem.size() : nullptr;
            for (std::size_t k = 0; k < mem.size(); ++k) {
                const double d = (offIn[k] - offOut).lengthSqr();
                if (balanced) row[k] = {d, std::uint32_t(k)};
                if (d < best) {
                    best = d;
                    nearestK = k;
                }
            }
            pickOf[mine[a]] = mem[nearestK];  // kept by a strand the balanced greedy leaves out
            if (balanced) nearest[a] = std::uint32_t(nearestK);
        }
        if (!balanced) return;
        const double cap = std::ceil(run.matching.balance * double(mine.size()) / double(mem.size()));
        detail::balancedMatch(cand, mine.size(), mem.size(), nearest, cap,
                              [&](std::uint32_t a, std::uint32_t k) { pickOf[mine[a]] = mem[k]; });
    });
}

/// World geometry and rotation-minimizing frames of the centres used, computed once each (the
/// output centres at the output's vertex count).
void centreGeometry(DetailTransferRun& run)
{
    const std::size_t nIn = run.nIn, nOut = run.nOut;
    run.outWorld.resize(nOut);
    run.inWorld.resize(nIn);
    run.outRmf.resize(nOut);
    run.inRmf.resize(nIn);
    run.inUsed.assign(nIn, 0);
    run.outUsed.assign(nOut, 0);
    for (std::uint32_t l : run.label) run.outUsed[l] = 1;
    for (std::size_t c = 0; c < nOut; ++c)
        if (run.outUsed[c]) run.inUsed[run.match[c]] = 1;
    const auto prepare = [&](const StrandSamples& s, std::size_t i, const ScalpFrame& aligned, int vertices,
                             std::vector<Vec3f>& world, std::vector<Frame>& rmf) {
        std::vector<float> row(std::size_t(3 * vertices));
        resampleRow(s.row(i), s.vertices, vertices, row.data());
        world.resize(std::size_t(vertices));
        sampleToWorld(row.data(), vertices, s.roots[i], s.frames[i], run.radius, world.data());
        rmf.resize(std::size_t(vertices));
        parallelTransportFrames(world.data(), world.size(), Vec3f(aligned.t), rmf.data());
    };
    run.forEach(nIn, [&](std::size_t c) { if (run.inUsed[c]) prepare(run.inC, c, run.inAligned[c], run.ns, run.inWorld[c], run.inRmf[c]); });
    run.forEach(nOut, [&](std::size_t c) { if (run.outUsed[c]) prepare(run.outCenters, c, run.outAligned[c], run.no, run.outWorld[c], run.outRmf[c]); });
}

/// DetailBlend::Edges: each used input centre's carrier and each used output centre's, at one
/// σ in world units (kCentreCarrierSmoothing of the matched input centre's vertices) so that a
/// centre onto itself gives its own carrier; strands' carriers at kStrandCarrierSmoothing of
/// their vertices (layStrand(), "Carrier smoothing"). Empty for the other blends.
void centreCarriers(DetailTransferRun& run)
{
    const std::size_t nIn = run.nIn, nOut = run.nOut;
    const int ns = run.ns, no = run.no;
    const double sigmaCentre = run.sigmaCentre;
    run.inCarrierLength.assign(nIn, 0.0);
    run.inCarrier.resize(run.edges ? nIn : 0);
    run.outCarrier.resize(run.edges ? nOut : 0);
    if (!run.edges) return;
    const auto toD = [](const std::vector<Vec3f>& p) {
        std::vector<Vec3d> q(p.size());
        for (std::size_t k = 0; k < p.size(); ++k) q[k] = Vec3d(p[k]);
        return q;
    };
    run.forEach(nIn, [&](std::size_t c) {
        if (!run.inUsed[c]) return;
        run.inCarrier[c] = detail::Carrier(toD(run.inWorld[c]), sigmaCentre, Vec3f(run.inAligned[c].t));
        run.inCarrierLength[c] = run.inCarrier[c].length();
    });
    run.forEach(nOut, [&](std::size_t c) {
        if (!run.outUsed[c]) return;
        const std::vector<Vec3d> p = toD(run.outWorld[c]);
        const double spacingIn = polylineLengthOf(toD(run.inWorld[run.match[c]])) / double(ns - 1);
        const double spacingOut = polylineLengthOf(p) / double(no - 1);
        run.outCarrier[c] = detail::Carrier(p, spacingOut > 0.0 ? sigmaCentre * spacingIn / spacingOut : sigmaCentre, Vec3f(run.outAligned[c].t));
    });
}

/// DetailBlend::Edges laid by DetailScale::ArcLength: the curl of each used input wisp
/// (wispCurl()), which its strands shorter than a period continue as past their end.
void wispCurls(DetailTransferRun& run)
{
    if (!run.edges || run.scale != DetailScale::ArcLength) return;
    std::vector<std::vector<std::uint32_t>> members(run.nIn);
    const std::vector<std::uint32_t>& label = *run.source.label;
    for (std::size_t s = 0; s < label.size(); ++s) members[label[s]].push_back(std::uint32_t(s));
    run.inCurl.assign(run.nIn, detail::Curl{});
    run.forEach(run.nIn, [&](std::size_t c) {
        if (!run.inUsed[c]) return;
        std::vector<std::vector<Vec3d>> strands;
        for (std::uint32_t s : members[c]) {
            const std::vector<Vec3f> w = worldOf(run.inS, s, run.radius);
            strands.emplace_back(w.begin(), w.end());
        }
        run.inCurl[c] = detail::wispCurl(strands, run.inCarrier[c], kCurlSmoothing * double(run.ns));
    });
}

/// Where each output vertex reads the input's displacement, a fractional input vertex: the
/// same for every strand of an output centre (computed once per centre used).
void readPositions(DetailTransferRun& run)
{
    const int ns = run.ns, no = run.no;
    run.atOf.resize(run.nOut);
    run.forEach(run.nOut, [&](std::size_t oc) {
        if (!run.outUsed[oc]) return;
        const std::vector<Vec3f>& cin = run.inWorld[run.match[oc]];
        const std::vector<Vec3f>& cout = run.outWorld[oc];
        std::vector<double>& at = run.atOf[oc];
        at.resize(static_cast<std::size_t>(no));
        if (run.scale != DetailScale::Index) {  // (Strand reads as ArcLength here)
            // At the output centre's arc length along the input centre, mirrored back and forth
            // beyond the input centre's end (DetailTransfer.h; DetailBlend::Edges: held at the end).
            const auto arcs = [&](const std::vector<Vec3f>& c) {
                std::vector<double> a(c.size(), 0.0);
                for (std::size_t k = 1; k < c.size(); ++k) a[k] = a[k - 1] + (Vec3d(c[k]) - Vec3d(c[k - 1])).length();
                return a;
            };
            const std::vector<double> ai = arcs(cin), ao = arcs(cout);
            const double Li = ai.back();
            for (std::size_t k = 0; k < at.size(); ++k) {
                double a = ao[k];
                if (Li > 0.0 && !run.edges) {
                    a = std::fmod(a, 2.0 * Li);
                    if (a > Li) a = 2.0 * Li - a;
                }
                const std::size_t j = std::size_t(std::upper_bound(ai.begin(), ai.end(), a) - ai.begin());
                if (j == 0) at[k] = 0.0;
                else if (j >= ai.size()) at[k] = double(ns - 1);
                else at[k] = double(j - 1) + (ai[j] > ai[j - 1] ? (a - ai[j - 1]) / (ai[j] - ai[j - 1]) : 0.0);
            }
        } else {
            // Vertex by vertex (the same fraction of the vertices).
            for (std::size_t k = 0; k < at.size(); ++k) at[k] = double(k) * double(ns - 1) / double(no - 1);
        }
    });
}

/// How far (head radii) a laid strand may rise above its root beyond its input strand and its
/// output centre before its offset is turned with the scalp's normal only (layStrand()).
constexpr double kRiseMargin = 0.05;

/// A strand's offset from its input centre (@a d, world) turned onto the output centre: with the
/// wisps' aligned frames (Eq. 4), or, @a normalOnly, as the root normal turns (layStrand(): when).
Vec3d turnOffset(const ScalpFrame& in, const ScalpFrame& out, const Vec3d& d, bool normalOnly)
{
    return normalOnly ? rotateOnto(in.n, out.n, d, in.t) : out.toWorld(in.toLocal(d));
}

/// The carrier of a strand laid on output centre @a oc past that centre's end, appended to @a q
/// until it reaches @a need (DetailScale::Strand and ArcLength). An output centre shorter than
/// its input centre @a ic ends where the strand may still run (DetailScale::Strand keeps its
/// length), and edges laid past a carrier's end keep its last frame: the curl that the strand's
/// own carrier holds (its offset from its centre) was lost there (the ponytail's level-1 strands
/// synthesized on centres under 0.9 of their input centre's length kept a median 0.81 of their
/// curl amplitude, 0.88 with this, seed 0). The carrier continues as the input centre does past the place
/// where the output centre ends, turned onto the output centre's end direction, plus the strand's
/// offset there (as layStrand() adds it), one point per input vertex.
void continueCarrier(const DetailTransferRun& run, std::uint32_t oc, std::uint32_t ic, const std::vector<Vec3f>& cg, const Vec3d& off0,
                     double need, bool normalOnly, std::vector<Vec3d>& q)
{
    const detail::Carrier& co = run.outCarrier[oc];
    const detail::Carrier& cin = run.inCarrier[ic];
    const std::vector<Vec3f>& ci = cin.points;
    const int ns = run.ns;
    const double atEnd = run.atOf[oc].back();
    if (ns < 2 || !(atEnd < double(ns - 1)) || !(need > co.length()) || co.frames.empty()) return;
    const ScalpFrame& mo = run.outAligned[oc];
    const ScalpFrame& mi = run.inAligned[ic];
    const auto at = [&](const std::vector<Vec3f>& p, double x) {
        const std::size_t j = std::min(std::size_t(x), std::size_t(ns - 2));
        const double t = x - double(j);
        return Vec3d(p[j]) * (1.0 - t) + Vec3d(p[j + 1]) * t;
    };
    const Vec3d ciEnd = at(ci, atEnd);
    const Vec3d base = q.back() - turnOffset(mi, mo, at(cg, atEnd) - ciEnd - off0, normalOnly);  // the output centre's end
    const Frame& fe = co.frames.back();
    const Vec3d from = Vec3d(cin.frames[std::min(std::size_t(std::lround(atEnd)), std::size_t(ns - 1))].t);
    double arc = co.length();
    for (std::size_t j = std::size_t(std::floor(atEnd)) + 1; j < std::size_t(ns) && arc <= need; ++j) {
        const Vec3d centre = base + rotateOnto(from, Vec3d(fe.t), Vec3d(ci[j]) - ciEnd, Vec3d(fe.n));
        const Vec3d p = centre + turnOffset(mi, mo, Vec3d(cg[j]) - Vec3d(ci[j]) - off0, normalOnly);
        arc += (p - q.back()).length();
        q.push_back(p);
    }
}

/// Step 5, DetailBlend::Edges: new strand @a i as the edges of its input strand (@a gin, world)
/// laid along the output centre's carrier (DetailTransfer.h, "Edges"); writes its row in its root
/// frame @a rf and returns its length.
double layStrand(const DetailTransferRun& run, std::size_t i, const std::vector<Vec3f>& gin, const ScalpFrame& rf, float* row)
{
    const std::uint32_t oc = run.label[i], ic = run.match[oc];
    const ScalpFrame& mo = run.outAligned[oc];
    const ScalpFrame& mi = run.inAligned[ic];
    const std::vector<double>& at = run.atOf[oc];  // where each output vertex reads
    const std::vector<Vec3d>& roots = run.roots;
    const int ns = run.ns, no = run.no;
    const DetailScale scale = run.scale;
    std::vector<Vec3d> strand(gin.size());
    for (std::size_t k = 0; k < gin.size(); ++k) strand[k] = Vec3d(gin[k]);
    std::vector<Vec3f> cg;
    std::vector<double> advance, frameShift;
    const std::vector<Vec3d> d = detail::strandEdges(strand, run.sigmaStrand, Vec3f(mi.t), &cg, &advance, &frameShift);
    double progress = 0.0;
    for (std::size_t k = 0; k < d.size(); ++k) progress += advance[k];
    // The output carrier: the output centre's, plus the strand's smooth offset from its
    // centre (carrier minus centre carrier, less the root offset) in the aligned root
    // frames, read where the output vertex reads (so a wisp gathers and parts as the input's).
    const detail::Carrier& centreCarrier = run.outCarrier[oc];
    const std::vector<Vec3f>& ci = run.inCarrier[ic].points;
    const Vec3d off0 = Vec3d(cg[0]) - Vec3d(ci[0]);
    const double li = run.inCarrierLength[ic], lo = centreCarrier.length();
    double lambda = 1.0, target = progress;  // Strand: its own length
    if (scale == DetailScale::Index) {
        lambda = li > 0.0 ? lo / li : 1.0;
        target = lambda * progress;
    } else if (scale == DetailScale::ArcLength) {
        // The output centre's length, as the other blends (each strand's own share of it,
        // its length over its input centre's, moved the ponytail's wisps onto the default
        // head 0.27 of their length from BASE's, against 0.08).
        target = std::max(progress + lo - li, progress * std::min(1.0, li > 0.0 ? lo / li : 1.0));
    }
    const detail::Curl& curl = run.inCurl.empty() ? detail::Curl{} : run.inCurl[ic];
    std::vector<Vec3f> rs(static_cast<std::size_t>(no));
    const auto lay = [&](bool normalOnly) {
        std::vector<Vec3d> q(static_cast<std::size_t>(no));
        for (std::size_t l = 0; l < q.size(); ++l) {
            const std::size_t j = std::min(std::size_t(at[l]), std::size_t(ns - 1));
            const double t = at[l] - double(j);
            Vec3d off = Vec3d(cg[j]) - Vec3d(ci[j]);
            if (t > 0.0 && j + 1 < std::size_t(ns)) off = off * (1.0 - t) + (Vec3d(cg[j + 1]) - Vec3d(ci[j + 1])) * t;
            q[l] = roots[i] + (Vec3d(centreCarrier.points[l]) - Vec3d(centreCarrier.points[0])) + turnOffset(mi, mo, off - off0, normalOnly);
        }
        if (scale != DetailScale::Index) continueCarrier(run, oc, ic, cg, off0, target, normalOnly, q);
        const detail::Carrier carrier(q, 0.0, Vec3f(mo.t));
        const std::vector<Vec3d> laid = detail::layEdges(d, advance, frameShift, lambda, carrier, roots[i], target, curl);
        std::vector<Vec3f> lf(laid.size());
        for (std::size_t k = 0; k < laid.size(); ++k) lf[k] = Vec3f(laid[k]);
        if (lf.size() < 2) lf.push_back(lf.back());
        // Laid whole at the output's vertex count, the strand's own vertices stay (resampling by
        // arc would cut its corners: samples even along the input, not along their chords).
        if (lf.size() == std::size_t(no)) rs = lf;
        else resamplePolyline(lf.data(), lf.size(), std::size_t(no), rs.data());
    };
    lay(false);
    // The wisps' aligned tangents follow their mean directions, for a loose wisp far from its
    // strands', and turned with them "beside the centre" can become "up": Ruby's short hair had a
    // tuft 29 units above the head (the example's hair 3.4). With wisps matched near their place
    // (synthesis), a strand rising above its root more than its input strand and its output centre
    // both do, by kRiseMargin, is laid again with the offset kept against the scalp. Not for every
    // strand: the TressFX ponytail's neighbouring wisps do differ in direction, and its strands then
    // kinked more; nor with wisps matched by shape from anywhere (transfer, synth --coarse), where
    // the frames carry a strand across the head (the ponytail on a small head: 0.086 -> 0.103).
    const Vec3d up = run.map.sphere().up;
    const auto rise = [&](const auto& p) {
        double r = 0.0;
        for (const auto& x : p) r = std::max(r, (Vec3d(x) - Vec3d(p[0])).dot(up));
        return r;
    };
    if (run.matching.place > 0.0 && rise(rs) > std::max(rise(gin), rise(centreCarrier.points)) + kRiseMargin * run.radius) lay(true);
    double len = 0.0;
    for (int l = 0; l < no; ++l) {
        const Vec3d p = l == 0 ? roots[i] : Vec3d(rs[std::size_t(l)]);
        const Vec3d q = rf.toLocal((p - roots[i]) / run.radius);
        row[3 * l] = float(q.x());
        row[3 * l + 1] = float(q.y());
        row[3 * l + 2] = float(q.z());
        if (l > 0) len += (Vec3d(rs[std::size_t(l)]) - Vec3d(rs[std::size_t(l - 1)])).length();
    }
    return len;
}

/// Step 5, DetailBlend::RootFrame and Paper (Eq. 5-8): new strand @a i as the displacements of its
/// input strand (@a gin, world) from its input centre, added to the output centre; writes its row
/// in its root frame @a rf and returns its length.
double blendStrand(const DetailTransferRun& run, std::size_t i, const std::vector<Vec3f>& gin, const ScalpFrame& rf, float* row)
{
    const std::uint32_t oc = run.label[i], ic = run.match[oc];
    const ScalpFrame& mo = run.outAligned[oc];
    const ScalpFrame& mi = run.inAligned[ic];
    const std::vector<Vec3f>& cin = run.inWorld[ic];
    const std::vector<Vec3f>& cout = run.outWorld[oc];
    const std::vector<double>& at = run.atOf[oc];  // where each output vertex reads
    const std::vector<Frame>& fin = run.inRmf[ic];
    const std::vector<Frame>& fout = run.outRmf[oc];
    const std::vector<Vec3d>& roots = run.roots;
    const int ns = run.ns, no = run.no;
    const auto inFrame = [&](const Frame& f, const Vec3d& w) { return Vec3d(f.t.dot(Vec3f(w)), f.n.dot(Vec3f(w)), f.b.dot(Vec3f(w))); };
    const auto outOf = [&](const Frame& f, const Vec3d& d) { return Vec3d(f.t) * d.x() + Vec3d(f.n) * d.y() + Vec3d(f.b) * d.z(); };
    const Vec3d rootIn = Vec3d(gin[0]) - Vec3d(cin[0]);
    const Vec3d betaShift = roots[i] - Vec3d(cout[0]) - outOf(fout[0], inFrame(fin[0], rootIn));
    // Eq. 5-6 per vertex of the input pair.
    std::vector<Vec3d> dA(static_cast<std::size_t>(ns)), dB(static_cast<std::size_t>(ns));
    for (int l = 0; l < ns; ++l) {
        const Vec3d dIn = Vec3d(gin[std::size_t(l)]) - Vec3d(cin[std::size_t(l)]);
        dA[std::size_t(l)] = mi.toLocal(dIn - rootIn);                          // Eq. 5
        dB[std::size_t(l)] = inFrame(fin[std::size_t(l)], dIn);                 // Eq. 6
    }
    const auto read = [&](const std::vector<Vec3d>& d) {
        std::vector<Vec3d> r(at.size());
        for (std::size_t k = 0; k < at.size(); ++k) {
            const std::size_t j = std::min(std::size_t(at[k]), std::size_t(ns - 1));
            const double t = at[k] - double(j);
            r[k] = j + 1 < std::size_t(ns) && t > 0.0 ? d[j] * (1.0 - t) + d[j + 1] * t : d[j];
        }
        return r;
    };
    dA = read(dA);
    dB = read(dB);
    double len = 0.0;
    Vec3d prev = roots[i];
    for (int l = 0; l < no; ++l) {
        const Vec3d& dAlpha = dA[std::size_t(l)];
        const Vec3d& dBeta = dB[std::size_t(l)];
        const Vec3d a = roots[i] + (Vec3d(cout[std::size_t(l)]) - Vec3d(cout[0])) + mo.toWorld(dAlpha);  // Eq. 8
        const Vec3d b = Vec3d(cout[std::size_t(l)]) + outOf(fout[std::size_t(l)], dBeta) + betaShift;
        const double s = run.blend == DetailBlend::RootFrame ? 0.0 : double(l) / double(no - 1);
        const Vec3d p = l == 0 ? roots[i] : a * (1.0 - s) + b * s;             // Eq. 7
        const Vec3d q = rf.toLocal((p - roots[i]) / run.radius);
        row[3 * l] = float(q.x());
        row[3 * l + 1] = float(q.y());
        row[3 * l + 2] = float(q.z());
        len += (p - prev).length();
        prev = p;
    }
    return len;
}
} // namespace

StrandSamples transferDetail(const TransferSource& source, const StrandSamples& outCenters,
                             const std::vector<Vec3d>& roots, const ScalpMap& map, int components,
                             std::vector<std::uint32_t>* outLabel, TransferStats* stats, DetailBlend blend, bool threaded,
                             openvdb::util::NullInterrupter* interrupter, const std::vector<std::uint32_t>* givenLabel,
                             DetailScale scale, int outVertices, const DetailMatchParams& matching)
{
    checkTransferInputs(source, outCenters, outVertices, matching);
    DetailTransferRun run(source, outCenters, roots, map, blend, scale, outVertices, matching, threaded);
    clusterRoots(run, givenLabel);
    alignCentres(run);
    matchClusters(run, components);
    if (interrupter && interrupter->wasInterrupted()) throw InterruptedError("detail transfer interrupted");
    matchStrands(run);
    centreGeometry(run);
    centreCarriers(run);
    wispCurls(run);
    readPositions(run);

    // 5. Every new strand.
    StrandSamples out;
    out.vertices = run.no;
    reserveHugePages(out.local, run.n * out.dim());  // fresh pages 2 MiB at a time (Memory.h)
    out.local.assign(run.n * out.dim(), 0.0f);
    out.roots = roots;
    out.scalp.resize(run.n);
    out.frames.resize(run.n);
    out.lengths.resize(run.n);
    run.forEach(run.n, [&](std::size_t i) {
        const std::vector<Vec3f> gin = worldOf(run.inS, run.pickOf[i], run.radius);  // its input strand (step 4)
        const Vec3d sc = map.toScalp(roots[i]);
        const ScalpFrame rf = map.frame(sc.x(), sc.y());
        const double len = run.edges ? layStrand(run, i, gin, rf, out.row(i)) : blendStrand(run, i, gin, rf, out.row(i));
        out.scalp[i] = sc;
        out.frames[i] = rf;
        out.lengths[i] = float(len);
    });
    if (outLabel) *outLabel = run.label;
    if (stats) {
        stats->clusters = 0;
        for (std::uint8_t u : run.outUsed) stats->clusters += u;
        stats->distinctSources = 0;
        for (std::uint8_t u : run.inUsed) stats->distinctSources += u;
    }
    return out;
}

} // namespace vdbhair
