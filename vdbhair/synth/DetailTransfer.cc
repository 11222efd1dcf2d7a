#include "DetailTransfer.h"

#include <vdbhair/Memory.h>

#include <vdbhair/Exceptions.h>
#include <vdbhair/Format.h>
#include <vdbhair/strands/Resample.h>
#include <vdbhair/strands/PointCloud.h>
#include <vdbhair/strands/Frames.h>
#include <vdbhair/synth/impl/BalancedMatch.h>

#include <vdbhair/Parallel.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <tuple>

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
        throw ValueError(std::string(where) + ": match balance " + formatNumber(balance) + ": 0 (off) or a finite factor of at least 1");
    if (candidates < 1) throw ValueError(std::string(where) + ": match candidates " + std::to_string(candidates) + ": must be at least 1");
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
/// Edges whose angle has a cosine within this of 1 (about 0.06 degrees) are collinear (strandEdges()):
/// a coarse polyline resampled to n_s (Curly_100 has 15-19 vertices a strand) is a run of collinear
/// edges between its corners. Each edge held in the carrier's frame at its own middle, a run came
/// out bent wherever the output carrier turned otherwise than the strand's own, every edge by a
/// little, and the bends added up: Curly_100 synthesized had strands with 2.6 times the turning of
/// the strand they copied (7.2 rad against 2.7).
constexpr double kCollinearCos = 5e-7;

/// A polyline's low-passed self (smoothPolyline(), σ in vertices) with its rotation-minimizing
/// frames (started from @a reference) and arc lengths: what detail is laid along.
struct Carrier
{
    std::vector<Vec3f> points;
    std::vector<Frame> frames;
    std::vector<double> arc;
    double length() const { return arc.empty() ? 0.0 : arc.back(); }

    Carrier() = default;
    Carrier(const std::vector<Vec3d>& p, double sigma, const Vec3f& reference)
    {
        std::vector<Vec3d> smooth(p.size());
        smoothPolyline(p.data(), p.size(), sigma, smooth.data());
        points.resize(p.size());
        for (std::size_t k = 0; k < p.size(); ++k) points[k] = Vec3f(smooth[k]);
        frames.resize(p.size());
        parallelTransportFrames(points.data(), points.size(), reference, frames.data());
        arc.assign(p.size(), 0.0);
        for (std::size_t k = 1; k < p.size(); ++k) arc[k] = arc[k - 1] + (smooth[k] - smooth[k - 1]).length();
    }

    /// The frame at arc length @a s (clamped to the carrier), between vertices by normalized
    /// interpolation; as three world axes (t, n, b).
    void frameAt(double s, Vec3d axes[3]) const
    {
        std::size_t j = 0;
        double u = 0.0;
        if (s >= arc.back()) {
            j = arc.size() - 1;
        } else if (s > 0.0) {
            j = std::size_t(std::upper_bound(arc.begin(), arc.end(), s) - arc.begin()) - 1;
            const double span = arc[j + 1] - arc[j];
            u = span > 0.0 ? (s - arc[j]) / span : 0.0;
        }
        Vec3d t = Vec3d(frames[j].t), n = Vec3d(frames[j].n);
        if (u > 0.0 && j + 1 < frames.size()) {
            t = t * (1.0 - u) + Vec3d(frames[j + 1].t) * u;
            n = n * (1.0 - u) + Vec3d(frames[j + 1].n) * u;
        }
        t = t.unitSafe();
        n = (n - t * n.dot(t)).unitSafe();
        axes[0] = t;
        axes[1] = n;
        axes[2] = t.cross(n);
    }
};

/// The rotation that takes unit @a from to unit @a to by the shortest arc, applied to @a v.
Vec3d rotateOnto(const Vec3d& from, const Vec3d& to, const Vec3d& v)
{
    const Vec3d axis = from.cross(to);
    const double s = axis.length(), c = from.dot(to);
    if (s < 1e-12) {
        if (c >= 0.0) return v;
        const Vec3d k = Vec3d(perpendicularTo(Vec3f(from))).unitSafe();  // half a turn about any perpendicular
        return k * (2.0 * k.dot(v)) - v;
    }
    const Vec3d k = axis / s;
    return v * c + k.cross(v) * s + k * (k.dot(v) * (1.0 - c));
}

/// One strand's detail as edges (DetailBlend::Edges): every edge in the frame of the strand's
/// carrier at the edge's middle; @a advance receives how far along the carrier each edge goes
/// (where the edge is laid along the output's carrier). (Turning each edge so that the edges'
/// local mean points along the carrier was tried: the ponytail onto the default head drifted
/// 0.082 of its length from BASE's wisps with it, 0.076 without.)
std::vector<Vec3d> strandEdges(const std::vector<Vec3d>& strand, double sigma, const Vec3f& reference, std::vector<Vec3f>* carrierPoints,
                               std::vector<double>* advance, std::vector<double>* frameShift)
{
    const Carrier c(strand, sigma, reference);
    if (carrierPoints) *carrierPoints = c.points;
    if (advance) {
        advance->resize(strand.size() - 1);
        for (std::size_t k = 0; k + 1 < strand.size(); ++k) (*advance)[k] = c.arc[k + 1] - c.arc[k];
    }
    const std::size_t K = strand.size() - 1;
    // Runs of collinear edges (a straight piece of a coarse polyline, resampled) share one frame,
    // the carrier's at the run's middle, so that they stay collinear wherever the output carrier
    // turns otherwise; every other edge takes the frame at its own middle (NaN in frameShift).
    std::vector<double> shift(K, std::numeric_limits<double>::quiet_NaN());
    for (std::size_t a = 0; a < K;) {
        std::size_t b = a + 1;
        while (b < K) {
            const Vec3d e0 = strand[b] - strand[b - 1], e1 = strand[b + 1] - strand[b];
            const double l0 = e0.length(), l1 = e1.length();
            if (!(l0 > 0.0 && l1 > 0.0) || e0.dot(e1) < (1.0 - kCollinearCos) * l0 * l1) break;
            ++b;
        }
        if (b - a > 1) {
            const double mid = 0.5 * (c.arc[a] + c.arc[b]);
            for (std::size_t k = a; k < b; ++k) shift[k] = mid - c.arc[k];
        }
        a = b;
    }
    std::vector<Vec3d> d(K);
    for (std::size_t k = 0; k < K; ++k) {
        Vec3d axes[3];
        c.frameAt(std::isnan(shift[k]) ? 0.5 * (c.arc[k] + c.arc[k + 1]) : c.arc[k] + shift[k], axes);
        const Vec3d e = strand[k + 1] - strand[k];
        d[k] = Vec3d(axes[0].dot(e), axes[1].dot(e), axes[2].dot(e));
    }
    if (frameShift) *frameShift = std::move(shift);
    return d;
}

/// The loop that repeats past a strand's end (DetailScale::ArcLength): edges [a, K) of @a d,
/// where the window of edges before a is most like the window ending the strand (so the repeat
/// joins as the strand itself continues: a period of a curl), at least a quarter of the strand
/// long. Turned as a whole: first so that its net step points along the carrier (a loop that
/// leans would step sideways at every repeat), then about the carrier by the angle that best
/// joins its start to the strand's end; @a twist receives that angle (each repeat turns by it).
std::vector<Vec3d> strandLoop(const std::vector<Vec3d>& d, double& twist)
{
    const std::size_t K = d.size();
    const std::size_t minLoop = std::max<std::size_t>(1, K / 4), window = std::max<std::size_t>(1, std::min<std::size_t>(4, K / 8));
    std::size_t a = 0;
    double best = std::numeric_limits<double>::max();
    for (std::size_t start = 1; start + minLoop <= K; ++start) {
        double e = 0.0;
        std::size_t w = 0;
        for (; w < window && w < start; ++w) e += (d[start - 1 - w] - d[K - 1 - w]).lengthSqr();
        e /= double(w);
        if (e < best) {
            best = e;
            a = start;
        }
    }
    std::vector<Vec3d> loop(d.begin() + std::ptrdiff_t(a), d.end());
    Vec3d net(0.0);
    for (const Vec3d& e : loop) net += e;
    if (net.length() > 1e-30)
        for (Vec3d& e : loop) e = rotateOnto(net.unitSafe(), Vec3d(1.0, 0.0, 0.0), e);
    // The twist about x̂ that takes the edges before the loop's start (as turned) onto the strand's last edges.
    double sn = 0.0, cs = 0.0;
    if (a > 0) {
        const Vec3d before = net.length() > 1e-30 ? rotateOnto(net.unitSafe(), Vec3d(1.0, 0.0, 0.0), d[a - 1]) : d[a - 1];
        const Vec3d& last = d[K - 1];
        sn = before.y() * last.z() - before.z() * last.y();
        cs = before.y() * last.y() + before.z() * last.z();
    }
    twist = (sn != 0.0 || cs != 0.0) ? std::atan2(sn, cs) : 0.0;
    return loop;
}

/// The strand of DetailBlend::Edges: @a d (strandEdges()) scaled by @a lambda, laid from
/// @a root in the frames of @a carrier at the place each edge reaches along it (its running
/// progress along x̂), until the progress reaches @a target: the strand's last edge is cut
/// there, or the strand's loop (strandLoop()) repeats after it, turned by one more twist each time.
std::vector<Vec3d> layEdges(const std::vector<Vec3d>& d, const std::vector<double>& advance, const std::vector<double>& frameShift,
                            double lambda, const Carrier& carrier, const Vec3d& root, double target)
{
    std::vector<Vec3d> out{root};
    out.reserve(d.size() + 1);
    double progress = 0.0;
    const auto lay = [&](const Vec3d& local, double step, double shift) {
        Vec3d e = local * lambda;
        step *= lambda;
        bool last = false;
        // (Within rounding of the target: a strand laid to its own length ends on its last edge.)
        if (progress + step >= target * (1.0 - 1e-9) && step > 0.0) {
            e *= (target - progress) / step;
            step = target - progress;
            last = true;
        }
        Vec3d axes[3];
        carrier.frameAt(std::isnan(shift) ? progress + 0.5 * step : progress + shift * lambda, axes);
        out.push_back(out.back() + axes[0] * e.x() + axes[1] * e.y() + axes[2] * e.z());
        progress += step;
        return last;
    };
    for (std::size_t k = 0; k < d.size(); ++k)
        if (lay(d[k], advance[k], frameShift[k])) return out;
    if (progress >= target * (1.0 - 1e-9)) return out;
    double twist = 0.0;
    std::vector<Vec3d> loop = strandLoop(d, twist);
    const auto stepOf = [](const std::vector<Vec3d>& l, double& arc) {
        double step = 0.0;
        arc = 0.0;
        for (const Vec3d& e : l) {
            step += e.x();
            arc += e.length();
        }
        return step;
    };
    double arc = 0.0, loopStep = stepOf(loop, arc);
    if (!(loopStep > 0.1 * arc)) {
        // A loop that hardly moves on (a closed curl): the whole strand repeats instead.
        loop = d;
        Vec3d net(0.0);
        for (const Vec3d& e : loop) net += e;
        if (net.length() > 1e-30)
            for (Vec3d& e : loop) e = rotateOnto(net.unitSafe(), Vec3d(1.0, 0.0, 0.0), e);
        twist = 0.0;
        loopStep = stepOf(loop, arc);
        if (!(loopStep > 0.0)) return out;
    }
    // (A cap on the repeats: targets are at most a few dozen strand lengths, kMaxOutputVertices.)
    constexpr std::size_t kMaxLaid = std::size_t(1) << 16;
    for (int r = 1; progress < target && out.size() < kMaxLaid; ++r) {
        const double c = std::cos(twist * r), sn = std::sin(twist * r);
        for (const Vec3d& e : loop)
            if (lay(Vec3d(e.x(), c * e.y() - sn * e.z(), sn * e.y() + c * e.z()), std::max(0.0, e.x()), std::numeric_limits<double>::quiet_NaN())) return out;
    }
    return out;
}
} // namespace

StrandSamples transferDetail(const TransferSource& source, const StrandSamples& outCenters,
                             const std::vector<Vec3d>& roots, const ScalpMap& map, int components,
                             std::vector<std::uint32_t>* outLabel, TransferStats* stats, DetailBlend blend, bool threaded,
                             openvdb::util::NullInterrupter* interrupter, const std::vector<std::uint32_t>* givenLabel,
                             DetailScale scale, int outVertices, const DetailMatchParams& matching)
{
    matching.validate("transferDetail");
    if (!source.strands || !source.centers || !source.label || source.strands->count() == 0 ||
        source.centers->count() == 0 || source.label->size() != source.strands->count())
        throw ValueError("transferDetail: the input level is incomplete or empty");
    if (outCenters.count() == 0) throw ValueError("transferDetail: no coarser output strands to transfer onto");
    const StrandSamples& inS = *source.strands;
    const StrandSamples& inC = *source.centers;
    const int ns = inS.vertices, nc = outCenters.vertices, no = outVertices > 0 ? outVertices : nc;
    if (inC.vertices != ns)
        throw ValueError("transferDetail: the input levels have different vertex counts per strand");
    if (ns < 2 || nc < 2 || no < 2) throw ValueError("transferDetail: strands need at least 2 vertices");
    const std::size_t dim = inS.dim(), nIn = inC.count(), nOut = outCenters.count(), n = roots.size();
    const double radius = map.radius();
    const auto forEach = [&](std::size_t count, auto&& fn) { forEachIndex(count, threaded, fn, 64); };

    // 1. Output clusters: each new root joins the nearest coarser output root (or its given centre).
    std::vector<std::uint32_t> label(n, 0);
    if (givenLabel) {
        if (givenLabel->size() != n)
            throw ValueError("transferDetail: " + std::to_string(givenLabel->size()) + " given centres for " + std::to_string(n) + " roots");
        for (std::uint32_t c : *givenLabel)
            if (c >= nOut) throw ValueError("transferDetail: given centre " + std::to_string(c) + " of " + std::to_string(nOut));
        label = *givenLabel;
    } else {
        PointCloud cloud{&outCenters.roots};
        PointKdTree tree(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(16));
        tree.buildIndex();
        forEach(n, [&](std::size_t i) {
            std::uint32_t idx;
            double d2;
            const double q[3] = {roots[i].x(), roots[i].y(), roots[i].z()};
            tree.knnSearch(q, 1, &idx, &d2);
            label[i] = idx;
        });
    }
    // 2. Aligned frames of every centre and their rows in them.
    std::vector<ScalpFrame> inAligned(nIn), outAligned(nOut);
    std::vector<float> rows((nIn + nOut) * dim);
    forEach(nIn, [&](std::size_t c) {
        inAligned[c] = alignedFrame(inC.row(c), ns, inC.frames[c]);
        reexpress(inC.row(c), ns, inC.frames[c], inAligned[c], rows.data() + c * dim);
    });
    forEach(nOut, [&](std::size_t c) {
        // Compared at the input's n_s vertices (the same row when the counts agree).
        std::vector<float> row(dim);
        resampleRow(outCenters.row(c), nc, ns, row.data());
        outAligned[c] = alignedFrame(row.data(), ns, outCenters.frames[c]);
        reexpress(row.data(), ns, outCenters.frames[c], outAligned[c], rows.data() + (nIn + c) * dim);
    });
    // Each output centre's strands (the load it puts on the input centre it takes).
    std::vector<std::size_t> load(nOut, 0);
    for (std::uint32_t l : label) ++load[l];
    const bool balanced = matching.balance > 0.0;
    if (balanced) {
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
            std::nth_element(v.begin(), v.begin() + std::ptrdiff_t(count / 2), v.end());
            return v[count / 2];
        };
        const double mIn = medianOf(0, nIn), mOut = medianOf(nIn, nOut);
        for (std::size_t r = 0; r < nIn + nOut; ++r) {
            const double m = r < nIn ? mIn : mOut;
            if (m > 1e-30)
                for (std::size_t k = 0; k < dim; ++k) rows[r * dim + k] = float(rows[r * dim + k] / m);
        }
    }
    // 3. Matching clusters through PCA features of both sets of centres.
    const Pca pca = fitPca(rows.data(), nIn + nOut, dim, components);
    const int nf = pca.components;
    std::vector<float> feat((nIn + nOut) * std::size_t(nf));
    forEach(nIn + nOut, [&](std::size_t r) { pca.project(rows.data() + r * dim, feat.data() + r * std::size_t(nf)); });
    std::vector<std::uint32_t> match(nOut, 0);
    const std::size_t K = balanced ? std::min<std::size_t>(nIn, std::size_t(matching.candidates)) : 1;
    std::vector<std::pair<double, std::uint32_t>> nearest(nOut * K);  // per output centre, its K nearest (distance, input)
    forEach(nOut, [&](std::size_t c) {
        const float* f = feat.data() + (nIn + c) * std::size_t(nf);
        std::vector<std::pair<double, std::uint32_t>> all(nIn);
        for (std::size_t j = 0; j < nIn; ++j) all[j] = {sampleDistance2(f, feat.data() + j * std::size_t(nf), std::size_t(nf)), std::uint32_t(j)};
        std::partial_sort(all.begin(), all.begin() + std::ptrdiff_t(K), all.end());  // ties to the lower index
        std::copy_n(all.begin(), K, nearest.begin() + std::ptrdiff_t(c * K));
        match[c] = all[0].second;
    });
    if (balanced) {
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
        for (std::uint32_t c : *source.label) share[c] += matching.balance * double(n) / double(inS.count());
        std::vector<double> used(nIn, 0.0);
        std::vector<std::uint8_t> done(nOut, 0);
        for (const auto& [d, c, j] : pairs) {
            if (done[c] || used[j] + double(load[c]) > share[j]) continue;
            done[c] = 1;
            used[j] += double(load[c]);
            match[c] = j;
        }
    }
    if (interrupter && interrupter->wasInterrupted()) throw InterruptedError("detail transfer interrupted");
    // Members of each input cluster.
    std::vector<std::vector<std::uint32_t>> members(nIn);
    for (std::uint32_t s = 0; s < inS.count(); ++s) members[(*source.label)[s]].push_back(s);
    // 4. Matching strands: each output strand takes a member of its matched input wisp by root
    // offset from the centre (aligned frames). Balanced, pairs are taken by increasing offset
    // distance and a member serves at most balance × its even share of the output wisp's strands
    // (so the output's strands take the input wisp's lengths and curls in its proportions: picked
    // by nearest offset alone, 100 strands of Curly_100 took a few members many times); the
    // paper's rule (balance 0) takes the nearest.
    std::vector<std::vector<std::uint32_t>> strandsOf(nOut);
    for (std::size_t i = 0; i < n; ++i) strandsOf[label[i]].push_back(std::uint32_t(i));
    std::vector<std::uint32_t> pickOf(n, 0);
    forEach(nOut, [&](std::size_t oc) {
        const std::vector<std::uint32_t>& mine = strandsOf[oc];
        const std::uint32_t ic = match[oc];
        const std::vector<std::uint32_t>& mem = members[ic];
        if (mine.empty() || mem.empty()) return;
        const ScalpFrame& mo = outAligned[oc];
        const ScalpFrame& mi = inAligned[ic];
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
        const double cap = std::ceil(matching.balance * double(mine.size()) / double(mem.size()));
        detail::balancedMatch(cand, mine.size(), mem.size(), nearest, cap,
                              [&](std::uint32_t a, std::uint32_t k) { pickOf[mine[a]] = mem[k]; });
    });
    // World geometry and rotation-minimizing frames of the centres used, computed once each.
    std::vector<std::vector<Vec3f>> outWorld(nOut), inWorld(nIn);
    std::vector<std::vector<Frame>> outRmf(nOut), inRmf(nIn);
    std::vector<std::uint8_t> inUsed(nIn, 0), outUsed(nOut, 0);
    for (std::uint32_t l : label) outUsed[l] = 1;
    for (std::size_t c = 0; c < nOut; ++c)
        if (outUsed[c]) inUsed[match[c]] = 1;
    // (The output centres at the output's vertex count.)
    const auto prepare = [&](const StrandSamples& s, std::size_t i, const ScalpFrame& aligned, int vertices,
                             std::vector<Vec3f>& world, std::vector<Frame>& rmf) {
        std::vector<float> row(std::size_t(3 * vertices));
        resampleRow(s.row(i), s.vertices, vertices, row.data());
        world.resize(std::size_t(vertices));
        sampleToWorld(row.data(), vertices, s.roots[i], s.frames[i], radius, world.data());
        rmf.resize(std::size_t(vertices));
        parallelTransportFrames(world.data(), world.size(), Vec3f(aligned.t), rmf.data());
    };
    forEach(nIn, [&](std::size_t c) { if (inUsed[c]) prepare(inC, c, inAligned[c], ns, inWorld[c], inRmf[c]); });
    forEach(nOut, [&](std::size_t c) { if (outUsed[c]) prepare(outCenters, c, outAligned[c], no, outWorld[c], outRmf[c]); });
    // DetailBlend::Edges: each used input centre's carrier and each used output centre's, at one
    // σ in world units (kCentreCarrierSmoothing of the matched input centre's vertices) so that a
    // centre onto itself gives its own carrier; strands' carriers at kStrandCarrierSmoothing of
    // their vertices (below, "Carrier smoothing").
    const bool edges = blend == DetailBlend::Edges;
    const double sigmaCentre = kCentreCarrierSmoothing * double(ns), sigmaStrand = kStrandCarrierSmoothing * double(ns);
    std::vector<double> inCarrierLength(nIn, 0.0);
    std::vector<Carrier> inCarrier(edges ? nIn : 0), outCarrier(edges ? nOut : 0);
    if (edges) {
        const auto toD = [](const std::vector<Vec3f>& p) {
            std::vector<Vec3d> q(p.size());
            for (std::size_t k = 0; k < p.size(); ++k) q[k] = Vec3d(p[k]);
            return q;
        };
        forEach(nIn, [&](std::size_t c) {
            if (!inUsed[c]) return;
            inCarrier[c] = Carrier(toD(inWorld[c]), sigmaCentre, Vec3f(inAligned[c].t));
            inCarrierLength[c] = inCarrier[c].length();
        });
        forEach(nOut, [&](std::size_t c) {
            if (!outUsed[c]) return;
            const std::vector<Vec3d> p = toD(outWorld[c]);
            const double spacingIn = polylineLengthOf(toD(inWorld[match[c]])) / double(ns - 1);
            const double spacingOut = polylineLengthOf(p) / double(no - 1);
            outCarrier[c] = Carrier(p, spacingOut > 0.0 ? sigmaCentre * spacingIn / spacingOut : sigmaCentre, Vec3f(outAligned[c].t));
        });
    }

    // Where each output vertex reads the input's displacement, a fractional input vertex: the
    // same for every strand of an output centre (computed once per centre used).
    std::vector<std::vector<double>> atOf(nOut);
    forEach(nOut, [&](std::size_t oc) {
        if (!outUsed[oc]) return;
        const std::vector<Vec3f>& cin = inWorld[match[oc]];
        const std::vector<Vec3f>& cout = outWorld[oc];
        std::vector<double>& at = atOf[oc];
        at.resize(static_cast<std::size_t>(no));
        if (scale != DetailScale::Index) {  // (Strand reads as ArcLength here)
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
                if (Li > 0.0 && !edges) {
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

    // 4-5. Every new strand.
    StrandSamples out;
    out.vertices = no;
    reserveHugePages(out.local, n * out.dim());  // fresh pages 2 MiB at a time (Memory.h)
    out.local.assign(n * out.dim(), 0.0f);
    out.roots = roots;
    out.scalp.resize(n);
    out.frames.resize(n);
    out.lengths.resize(n);
    forEach(n, [&](std::size_t i) {
        const std::uint32_t oc = label[i], ic = match[oc];
        const ScalpFrame& mo = outAligned[oc];
        const ScalpFrame& mi = inAligned[ic];
        const std::uint32_t pick = pickOf[i];  // step 4
        const std::vector<Vec3f> gin = worldOf(inS, pick, radius);
        const Vec3d sc = map.toScalp(roots[i]);
        const ScalpFrame rf = map.frame(sc.x(), sc.y());
        float* row = out.row(i);
        const std::vector<Vec3f>& cin = inWorld[ic];
        const std::vector<Vec3f>& cout = outWorld[oc];
        const std::vector<double>& at = atOf[oc];  // where each output vertex reads
        if (edges) {
            // The strand's own edges laid along the output centre's carrier (DetailTransfer.h, "Edges").
            std::vector<Vec3d> strand(gin.size());
            for (std::size_t k = 0; k < gin.size(); ++k) strand[k] = Vec3d(gin[k]);
            std::vector<Vec3f> cg;
            std::vector<double> advance, frameShift;
            const std::vector<Vec3d> d = strandEdges(strand, sigmaStrand, Vec3f(mi.t), &cg, &advance, &frameShift);
            double progress = 0.0;
            for (std::size_t k = 0; k < d.size(); ++k) progress += advance[k];
            // The output carrier: the output centre's, plus the strand's smooth offset from its
            // centre (carrier minus centre carrier, less the root offset) in the aligned root
            // frames, read where the output vertex reads (so a wisp gathers and parts as the input's).
            const Carrier& centreCarrier = outCarrier[oc];
            const std::vector<Vec3f>& ci = inCarrier[ic].points;
            std::vector<Vec3d> q(static_cast<std::size_t>(no));
            const Vec3d off0 = Vec3d(cg[0]) - Vec3d(ci[0]);
            for (std::size_t l = 0; l < q.size(); ++l) {
                const std::size_t j = std::min(std::size_t(at[l]), std::size_t(ns - 1));
                const double t = at[l] - double(j);
                Vec3d off = Vec3d(cg[j]) - Vec3d(ci[j]);
                if (t > 0.0 && j + 1 < std::size_t(ns)) off = off * (1.0 - t) + (Vec3d(cg[j + 1]) - Vec3d(ci[j + 1])) * t;
                q[l] = roots[i] + (Vec3d(centreCarrier.points[l]) - Vec3d(centreCarrier.points[0])) + mo.toWorld(mi.toLocal(off - off0));
            }
            const Carrier carrier(q, 0.0, Vec3f(mo.t));
            const double li = inCarrierLength[ic], lo = centreCarrier.length();
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
            const std::vector<Vec3d> laid = layEdges(d, advance, frameShift, lambda, carrier, roots[i], target);
            std::vector<Vec3f> lf(laid.size()), rs(static_cast<std::size_t>(no));
            for (std::size_t k = 0; k < laid.size(); ++k) lf[k] = Vec3f(laid[k]);
            if (lf.size() < 2) lf.push_back(lf.back());
            // Laid whole at the output's vertex count, the strand's own vertices stay (resampling by
            // arc would cut its corners: samples even along the input, not along their chords).
            if (lf.size() == std::size_t(no)) rs = lf;
            else resamplePolyline(lf.data(), lf.size(), std::size_t(no), rs.data());
            double len = 0.0;
            for (int l = 0; l < no; ++l) {
                const Vec3d p = l == 0 ? roots[i] : Vec3d(rs[std::size_t(l)]);
                const Vec3d q = rf.toLocal((p - roots[i]) / radius);
                row[3 * l] = float(q.x());
                row[3 * l + 1] = float(q.y());
                row[3 * l + 2] = float(q.z());
                if (l > 0) len += (Vec3d(rs[std::size_t(l)]) - Vec3d(rs[std::size_t(l - 1)])).length();
            }
            out.scalp[i] = sc;
            out.frames[i] = rf;
            out.lengths[i] = float(len);
            return;
        }
        const std::vector<Frame>& fin = inRmf[ic];
        const std::vector<Frame>& fout = outRmf[oc];
        // 5. Eq. 5-8.
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
            const double s = blend == DetailBlend::RootFrame ? 0.0 : double(l) / double(no - 1);
            const Vec3d p = l == 0 ? roots[i] : a * (1.0 - s) + b * s;             // Eq. 7
            const Vec3d q = rf.toLocal((p - roots[i]) / radius);
            row[3 * l] = float(q.x());
            row[3 * l + 1] = float(q.y());
            row[3 * l + 2] = float(q.z());
            len += (p - prev).length();
            prev = p;
        }
        out.scalp[i] = sc;
        out.frames[i] = rf;
        out.lengths[i] = float(len);
    });
    if (outLabel) *outLabel = label;
    if (stats) {
        stats->clusters = 0;
        for (std::uint8_t u : outUsed) stats->clusters += u;
        stats->distinctSources = 0;
        for (std::uint8_t u : inUsed) stats->distinctSources += u;
    }
    return out;
}

} // namespace vdbhair
