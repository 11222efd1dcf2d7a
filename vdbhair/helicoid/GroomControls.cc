#include "GroomControls.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/Format.h>
#include <vdbhair/Parallel.h>
#include <vdbhair/Progress.h>
#include <vdbhair/Random.h>
#include <vdbhair/helicoid/PointInterpolation.h>
#include <vdbhair/helicoid/Waviness.h>
#include <vdbhair/strands/Frames.h>
#include <vdbhair/strands/Measures.h>
#include <vdbhair/strands/Resample.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <unordered_map>

namespace vdbhair {

namespace {

// The controls' own random streams (Random.h: seeded by seed, root, stream).
constexpr std::uint64_t kDensityStream = 0x64656e73;  // "dens"
constexpr std::uint64_t kClumpStream = 0x636c756d;    // "clum"
constexpr std::uint64_t kCurlStream = 0x6375726c;     // "curl"
constexpr std::uint64_t kFrizzStream = 0x6672697a;    // "friz"

Vec3d toD(const Vec3f& v) { return Vec3d(v.x(), v.y(), v.z()); }
Vec3f toF(const Vec3d& v) { return Vec3f(float(v.x()), float(v.y()), float(v.z())); }

/// The point at arc length @a s of a polyline with arc lengths @a arc (clamped to its ends).
Vec3d pointAt(const Vec3f* p, const std::vector<double>& arc, double s)
{
    const std::size_t n = arc.size();
    if (s <= 0.0) return toD(p[0]);
    if (s >= arc.back()) return toD(p[n - 1]);
    const std::size_t k = std::size_t(std::upper_bound(arc.begin(), arc.end(), s) - arc.begin());  // arc[k-1] <= s < arc[k]
    const double len = arc[k] - arc[k - 1];
    const double f = len > 0.0 ? (s - arc[k - 1]) / len : 0.0;
    return toD(p[k - 1]) + (toD(p[k]) - toD(p[k - 1])) * f;
}

void arcOf(const Vec3f* p, std::size_t n, std::vector<double>& arc)
{
    arc.resize(n);
    arcLengths(p, n, arc.data());
}

/// A new set with the same strands and @a counts vertices each (offsets only; positions sized).
StrandSet withCounts(const std::vector<std::uint32_t>& counts, std::size_t maxVertices, const std::string& what)
{
    StrandSet out;
    out.offsets.assign(counts.size() + 1, 0);
    std::uint64_t total = 0;
    for (std::size_t i = 0; i < counts.size(); ++i) {
        total += counts[i];
        if (total > maxVertices || total > std::numeric_limits<std::uint32_t>::max()) {
            throw LimitError(what + " would make more than " + std::to_string(std::min<std::uint64_t>(maxVertices, std::numeric_limits<std::uint32_t>::max())) +
                             " vertices (the cap, --max-vertices; 12 bytes a vertex)");
        }
        out.offsets[i + 1] = std::uint32_t(total);
    }
    out.positions.resize(total);
    return out;
}

/// Integer cell of @a p at cell size @a h from @a origin, packed (21 bits a coordinate).
std::uint64_t cellKey(const Vec3d& p, const Vec3d& origin, double h, int dx = 0, int dy = 0, int dz = 0)
{
    const auto c = [&](int axis, int d) { return std::uint64_t(std::int64_t(std::floor((p[axis] - origin[axis]) / h)) + d + 1) & 0x1fffff; };
    return c(0, dx) | (c(1, dy) << 21) | (c(2, dz) << 42);
}

} // namespace

void validateGroomParams(const GroomParams& p)
{
    const ClumpParams& c = p.clump;
    const CurlParams& k = p.curl;
    if (!(c.radius >= 0.0) || !std::isfinite(c.radius)) throw ValueError("--clump-radius " + formatNumber(c.radius) + ": must be a length of 0 (no clumps) or more");
    if (!(c.tightness >= 0.0 && c.tightness <= 1.0)) throw ValueError("--clump-tightness " + formatNumber(c.tightness) + ": must be in [0, 1]");
    if (!(c.profile > 0.0) || !std::isfinite(c.profile)) throw ValueError("--clump-profile " + formatNumber(c.profile) + ": must be a positive exponent");
    if (!(c.likeness >= 0.0) || !std::isfinite(c.likeness)) throw ValueError("--clump-likeness " + formatNumber(c.likeness) + ": must be 0 (any shape) or a positive fraction");
    if (!(k.amplitude >= 0.0) || !std::isfinite(k.amplitude)) throw ValueError("--curl " + formatNumber(k.amplitude) + ": must be an amplitude of 0 (no curl) or more");
    if (!(k.frequency >= 0.0) || !std::isfinite(k.frequency)) throw ValueError("--curl-frequency " + formatNumber(k.frequency) + ": must be 0 or more radians per unit length");
    if (k.amplitude > 0.0 && !(k.frequency > 0.0)) throw ValueError("--curl " + formatNumber(k.amplitude) + " needs --curl-frequency (radians per unit length; one turn every 2 pi / b)");
    if (!(k.frizz >= 0.0) || !std::isfinite(k.frizz)) throw ValueError("--frizz " + formatNumber(k.frizz) + ": must be a length of 0 (no frizz) or more");
}

const ParamTable<GroomParams>& groomParameters()
{
    using P = GroomParams;
    static const ParamTable<P> table = [] {
        ParamTable<P> t;
        auto radius = makeParam<P>("clump-radius", "Clumps: hairs within this distance of a clump centre are pulled to its hair", "world units",
                                   member<P>([](P& p) -> double& { return p.clump.radius; }));
        radius.min = 0.0;
        radius.zeroMeans = "no clumps";
        t.push_back(radius);
        auto tightness = makeParam<P>("clump-tightness", "Clumps: the share of the way to the centre's hair a tip moves", "",
                                      member<P>([](P& p) -> double& { return p.clump.tightness; }));
        tightness.min = 0.0;
        tightness.max = 1.0;
        t.push_back(tightness);
        auto profile = makeParam<P>("clump-profile", "Clumps: the pull at a fraction t of the length is tightness * t^profile (higher: looser near the root)", "",
                                    member<P>([](P& p) -> double& { return p.clump.profile; }));
        profile.min = 0.0;
        profile.aboveMin = true;
        t.push_back(profile);
        auto likeness = makeParam<P>("clump-likeness", "Clumps: hairs shaped unlike their centre by more than this likeness distance stay out", "",
                                     member<P>([](P& p) -> double& { return p.clump.likeness; }));
        likeness.min = 0.0;
        likeness.zeroMeans = "any shape";
        t.push_back(likeness);
        auto curl = makeParam<P>("curl", "Curl: the amplitude a of Eq. 4, about each hair", "world units", member<P>([](P& p) -> double& { return p.curl.amplitude; }));
        curl.min = 0.0;
        curl.zeroMeans = "no curl";
        t.push_back(curl);
        auto frequency = makeParam<P>("curl-frequency", "Curl: b of Eq. 4 (a turn every 2 pi / b)", "radians per unit length",
                                      member<P>([](P& p) -> double& { return p.curl.frequency; }));
        frequency.min = 0.0;
        t.push_back(frequency);
        auto frizz = makeParam<P>("frizz", "Frizz: the deviation of a random offset at the tip, from 0 at the root", "world units",
                                  member<P>([](P& p) -> double& { return p.curl.frizz; }));
        frizz.min = 0.0;
        frizz.zeroMeans = "no frizz";
        t.push_back(frizz);
        return t;
    }();
    return table;
}

std::vector<char> rootsKept(std::size_t R, const std::vector<float>& density, const std::vector<float>& length, std::uint64_t seed)
{
    if (!density.empty() && density.size() != R) throw ValueError(std::to_string(density.size()) + " density values for " + std::to_string(R) + " roots: one per root");
    if (!length.empty() && length.size() != R) throw ValueError(std::to_string(length.size()) + " length values for " + std::to_string(R) + " roots: one per root");
    std::vector<char> keep(R, 1);
    for (std::size_t i = 0; i < R; ++i) {
        if (!density.empty()) {
            const float d = density[i];
            if (!(d >= 0.f && d <= 1.f)) throw ValueError("density " + formatNumber(d) + " at root " + std::to_string(i) + ": must be in [0, 1] (the share of roots kept)");
            if (d < 1.f && !(Rng(seed, i, kDensityStream).uniform() < double(d))) keep[i] = 0;
        }
        if (!length.empty()) {
            const float l = length[i];
            if (!(l >= 0.f && l <= 1.f)) throw ValueError("length " + formatNumber(l) + " at root " + std::to_string(i) + ": must be in [0, 1] (a share of the hair's length; 0 grows none)");
            if (l <= 0.f) keep[i] = 0;
        }
    }
    return keep;
}

std::size_t cutStrands(StrandSet& strands, const std::vector<float>& fraction, bool threaded)
{
    const std::size_t S = strands.numStrands();
    if (fraction.size() != S) throw ValueError(std::to_string(fraction.size()) + " length fractions for " + std::to_string(S) + " strands: one per strand");
    for (std::size_t i = 0; i < S; ++i) {
        if (!(fraction[i] > 0.f && fraction[i] <= 1.f)) throw ValueError("length " + formatNumber(fraction[i]) + " of strand " + std::to_string(i) + ": must be in (0, 1]");
    }
    // Where each strand is cut: the last whole vertex k and the share f of segment k..k+1 kept.
    std::vector<std::uint32_t> counts(S), last(S);
    std::vector<float> share(S, 0.f);
    forEachIndex(S, threaded, [&](std::size_t i) {
        const std::size_t n = strands.size(i);
        counts[i] = std::uint32_t(n);
        last[i] = std::uint32_t(n - 1);
        if (fraction[i] >= 1.f) return;
        std::vector<double> arc;
        arcOf(strands.data(i), n, arc);
        const double cut = double(fraction[i]) * arc.back();
        std::size_t k = std::size_t(std::upper_bound(arc.begin(), arc.end(), cut) - arc.begin()) - 1;  // arc[k] <= cut
        k = std::min(k, n - 2);
        const double len = arc[k + 1] - arc[k];
        double f = len > 0.0 ? std::clamp((cut - arc[k]) / len, 0.0, 1.0) : 0.0;
        // A cut within a millionth of a segment of a vertex is on it (no sliver of a segment).
        if (f < 1e-6) f = 0.0;
        else if (f > 1.0 - 1e-6) f = 0.0, ++k;
        last[i] = std::uint32_t(k);
        share[i] = float(f);
        counts[i] = std::uint32_t(k + (f > 0.0 ? 2 : 1));
        if (counts[i] < 2) counts[i] = 2, share[i] = float(f);  // a cut inside the first segment keeps its root and the cut point
    }, 1024);
    std::size_t cutCount = 0;
    for (std::size_t i = 0; i < S; ++i) cutCount += fraction[i] < 1.f ? 1 : 0;
    if (cutCount == 0) return 0;
    StrandSet out = withCounts(counts, std::numeric_limits<std::uint32_t>::max(), "cutting");
    const bool th = !strands.thickness.empty(), tr = !strands.transparency.empty(), co = !strands.color.empty();
    if (th) out.thickness.resize(out.numVertices());
    if (tr) out.transparency.resize(out.numVertices());
    if (co) out.color.resize(out.numVertices());
    forEachIndex(S, threaded, [&](std::size_t i) {
        const std::size_t b = strands.begin(i), o = out.begin(i), m = out.size(i);
        for (std::size_t k = 0; k < m; ++k) {
            // Whole vertices up to last[i], then the cut point share[i] of the way to the next.
            const std::size_t v = std::min<std::size_t>(k, last[i]);
            const float f = k > last[i] ? share[i] : 0.f;
            const std::size_t w = std::min<std::size_t>(v + 1, strands.size(i) - 1);
            out.positions[o + k] = strands.positions[b + v] + (strands.positions[b + w] - strands.positions[b + v]) * f;
            if (th) out.thickness[o + k] = strands.thickness[b + v] + (strands.thickness[b + w] - strands.thickness[b + v]) * f;
            if (tr) out.transparency[o + k] = strands.transparency[b + v] + (strands.transparency[b + w] - strands.transparency[b + v]) * f;
            if (co) out.color[o + k] = strands.color[b + v] + (strands.color[b + w] - strands.color[b + v]) * f;
        }
    }, 1024);
    out.rootUV = std::move(strands.rootUV);
    out.strandId = std::move(strands.strandId);
    out.defaults = strands.defaults;
    strands = std::move(out);
    return cutCount;
}

std::vector<std::uint32_t> clumpCentres(const std::vector<Vec3d>& roots, double radius, const std::vector<std::uint32_t>& groups,
                                        std::uint64_t seed, bool threaded)
{
    // On a hash grid of cell size radius: a root's centres within the radius lie in the 27 cells around it.
    const std::size_t S = roots.size();
    if (!(radius > 0.0) || !std::isfinite(radius)) throw ValueError("--clump-radius " + formatNumber(radius) + ": must be a positive length");
    if (!groups.empty() && groups.size() != S) throw ValueError(std::to_string(groups.size()) + " group ids for " + std::to_string(S) + " roots: one per root");
    std::vector<std::uint32_t> centre(S);
    if (S == 0) return centre;
    Vec3d lo(std::numeric_limits<double>::max()), hi(-std::numeric_limits<double>::max());
    for (const Vec3d& r : roots) lo = openvdb::math::minComponent(lo, r), hi = openvdb::math::maxComponent(hi, r);
    const double h = radius;
    const Vec3d extent = (hi - lo) / h;
    if (!(std::max({extent.x(), extent.y(), extent.z()}) < double(1 << 20))) {
        throw ValueError("--clump-radius " + formatNumber(radius) + ": over 2^20 clumps across the roots' extent of " +
                         formatNumber(std::max({hi.x() - lo.x(), hi.y() - lo.y(), hi.z() - lo.z()})) + "; give a larger radius");
    }
    std::vector<std::pair<std::uint64_t, std::uint32_t>> order(S);
    forEachIndex(S, threaded, [&](std::size_t i) { order[i] = {Rng(seed, i, kClumpStream).next(), std::uint32_t(i)}; }, 4096);
    std::sort(order.begin(), order.end());
    std::unordered_map<std::uint64_t, std::vector<std::uint32_t>> grid;
    grid.reserve(S / 4 + 16);
    const double r2 = radius * radius;
    auto nearestCentre = [&](std::size_t i, double& best) {
        std::uint32_t found = std::uint32_t(-1);
        best = std::numeric_limits<double>::max();
        for (int dz = -1; dz <= 1; ++dz)
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) {
                    const auto it = grid.find(cellKey(roots[i], lo, h, dx, dy, dz));
                    if (it == grid.end()) continue;
                    for (std::uint32_t c : it->second) {
                        if (!groups.empty() && groups[c] != groups[i]) continue;
                        const double d2 = (roots[c] - roots[i]).lengthSqr();
                        if (d2 < best || (d2 == best && c < found)) best = d2, found = c;
                    }
                }
        return found;
    };
    for (const auto& e : order) {
        double d2;
        if (nearestCentre(e.second, d2) != std::uint32_t(-1) && d2 < r2) continue;
        grid[cellKey(roots[e.second], lo, h)].push_back(e.second);
    }
    forEachIndex(S, threaded, [&](std::size_t i) {
        double d2;
        centre[i] = nearestCentre(i, d2);  // every root was tested, so one lies within the radius (or it is one)
    }, 1024);
    return centre;
}

namespace {

/// Curl (Eq. 4 about each hair's rotation-minimizing frame), each hair resampled to
/// kCurlVerticesPerTurn; hairs of one clump (@a centre, empty without clumps: all hairs) curl in
/// step. Returns the vertices added.
std::size_t curlStrands(StrandSet& strands, const GroomParams& params, const std::vector<std::uint32_t>& centre, bool threaded,
                        openvdb::util::NullInterrupter* interrupter)
{
    const CurlParams& kp = params.curl;
    const std::size_t S = strands.numStrands();
    const double wavelength = 2.0 * M_PI / kp.frequency;
    std::vector<std::uint32_t> counts(S);
    forEachIndex(S, threaded, [&](std::size_t i) {
        const std::size_t n = strands.size(i);
        const double turns = polylineLength(strands.data(i), n) / wavelength;
        counts[i] = std::uint32_t(std::max<double>(double(n), std::min(std::ceil(turns * kCurlVerticesPerTurn) + 1.0, 1e9)));
    }, 1024);
    StrandSet out = withCounts(counts, params.maxVertices, "curl (" + std::to_string(int(kCurlVerticesPerTurn)) + " vertices a turn)");
    ProgressCounter progress(interrupter, "curling", S, "strands");
    forEachRange(S, threaded, 256, [&](const tbb::blocked_range<std::size_t>& r) {
        if (progress.stopped()) return;
        std::vector<Vec3f> pts;
        std::vector<Frame> frames;
        HelicoidTrace trace;
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
            const std::size_t m = out.size(i);
            pts.resize(m);
            if (m == strands.size(i)) std::copy(strands.data(i), strands.data(i) + m, pts.begin());
            else resamplePolyline(strands.data(i), strands.size(i), m, pts.data());
            // A frame that starts alike on every hair (world x, else y, across the root
            // tangent), so hairs of one clump curl in step.
            frames.resize(m);
            const Vec3f t0 = (pts[1] - pts[0]).unitSafe();
            const Vec3f ref = std::abs(t0.x()) < 0.9f ? Vec3f(1.f, 0.f, 0.f) : Vec3f(0.f, 1.f, 0.f);
            parallelTransportFrames(pts.data(), m, ref, frames.data());
            trace.points.resize(m);
            trace.frames.resize(m);
            trace.arc.resize(m);
            arcLengths(pts.data(), m, trace.arc.data());
            for (std::size_t k = 0; k < m; ++k) {
                trace.points[k] = toD(pts[k]);
                trace.frames[k] = FrameD{toD(frames[k].t), toD(frames[k].n), toD(frames[k].b)};
            }
            WavinessParams w;
            w.amplitude = kp.amplitude;
            w.frequency = kp.frequency;
            // One phase for every hair of a clump (ringlets), or for all hairs without clumps (waves in step).
            w.phase = 2.0 * M_PI * Rng(params.seed, centre.empty() ? 0 : centre[i], kCurlStream).uniform();
            w.ramp = wavelength;
            Rng unused(0);
            applyWaviness(trace, w, unused, out.data(i));
        }
        progress.add(r.size());
    });
    if (progress.stopped()) throw InterruptedError("curl: interrupted");
    const std::size_t added = out.numVertices() - strands.numVertices();
    // Per-vertex attributes do not survive resampling; interpolated hair has none.
    out.rootUV = std::move(strands.rootUV);
    out.strandId = std::move(strands.strandId);
    out.defaults = strands.defaults;
    strands = std::move(out);
    return added;
}

/// Clumps: each member towards its centre's hair at the same arc length (centres stay as they
/// are). Returns the hairs that joined their clump.
std::size_t clumpStrands(StrandSet& strands, const ClumpParams& cp, const std::vector<std::uint32_t>& centre, bool threaded,
                         openvdb::util::NullInterrupter* interrupter)
{
    const std::size_t S = strands.numStrands();
    std::vector<char> joined(S, 0);
    ProgressCounter progress(interrupter, "clumping", S, "strands");
    forEachRange(S, threaded, 256, [&](const tbb::blocked_range<std::size_t>& r) {
        if (progress.stopped()) return;
        std::vector<double> ap, aq;
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
            const std::uint32_t c = centre[i];
            if (c == i || cp.tightness <= 0.0) continue;
            Vec3f* p = strands.data(i);
            const Vec3f* q = strands.data(c);
            const std::size_t n = strands.size(i), m = strands.size(c);
            if (cp.likeness > 0.0 && likenessDistance(p, n, q, m) > cp.likeness) continue;
            arcOf(p, n, ap);
            arcOf(q, m, aq);
            const double lp = ap.back(), lq = aq.back();
            if (!(lp > 0.0)) continue;
            const Vec3d qEnd = toD(q[m - 1]), pAtEnd = pointAt(p, ap, lq);
            for (std::size_t k = 1; k < n; ++k) {
                const double s = ap[k];
                const double t = s / lp;
                const double pull = cp.tightness * (cp.profile == 1.0 ? t : std::pow(t, cp.profile));
                const Vec3d own = toD(p[k]);
                // Beyond the centre's tip a longer hair keeps its own shape from there on.
                const Vec3d target = s <= lq ? pointAt(q, aq, s) : qEnd + (own - pAtEnd);
                p[k] = toF(own + (target - own) * pull);
            }
            joined[i] = 1;
        }
        progress.add(r.size());
    });
    if (progress.stopped()) throw InterruptedError("clumping: interrupted");
    std::size_t clumped = 0;
    for (char j : joined) clumped += std::size_t(j);
    return clumped;
}

/// Frizz: a random offset across the hair, its deviation growing from 0 at the root to
/// @a frizz at the tip.
void frizzStrands(StrandSet& strands, double frizz, std::uint64_t seed, bool threaded)
{
    const std::size_t S = strands.numStrands();
    forEachIndex(S, threaded, [&](std::size_t i) {
        Vec3f* p = strands.data(i);
        const std::size_t n = strands.size(i);
        std::vector<double> arc;
        arcOf(p, n, arc);
        if (!(arc.back() > 0.0)) return;  // a strand of zero length has no across
        const std::vector<Vec3f> before(p, p + n);
        Rng rng(seed, i, kFrizzStream);
        for (std::size_t k = 1; k < n; ++k) {
            const Vec3f t = (before[std::min(k + 1, n - 1)] - before[k - 1]).unitSafe();
            const Vec3f a = perpendicularTo(t), b = t.cross(a);
            double g1, g2;
            rng.normalPair(g1, g2);
            const double sd = frizz * arc[k] / arc.back();
            p[k] = before[k] + a * float(sd * g1) + b * float(sd * g2);
        }
    }, 256);
}

} // namespace

GroomStats applyGroomControls(StrandSet& strands, const GroomParams& params, const std::vector<std::uint32_t>& groups, bool threaded,
                              openvdb::util::NullInterrupter* interrupter)
{
    validateGroomParams(params);
    const std::size_t S = strands.numStrands();
    if (!groups.empty() && groups.size() != S) throw ValueError(std::to_string(groups.size()) + " group ids for " + std::to_string(S) + " strands: one per strand");
    GroomStats stats;
    if (S == 0) return stats;
    std::vector<Vec3d> roots(S);
    for (std::size_t i = 0; i < S; ++i) roots[i] = toD(strands.root(i));

    // Clump centres first (the curl's phase is the clump's).
    std::vector<std::uint32_t> centre;  // #S: the centre each root joins (itself for a centre)
    if (params.clump.radius > 0.0) {
        centre = clumpCentres(roots, params.clump.radius, groups, params.seed, threaded);
        for (std::size_t i = 0; i < S; ++i) stats.clumps += centre[i] == i ? 1 : 0;
    }
    if (params.curl.amplitude > 0.0) {
        stats.addedVertices = curlStrands(strands, params, centre, threaded, interrupter);
        stats.curled = S;
    }
    if (!centre.empty()) stats.clumped = clumpStrands(strands, params.clump, centre, threaded, interrupter);
    if (params.curl.frizz > 0.0) frizzStrands(strands, params.curl.frizz, params.seed, threaded);
    return stats;
}

} // namespace vdbhair
