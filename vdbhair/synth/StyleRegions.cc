#include "StyleRegions.h"

#include <vdbhair/Parallel.h>
#include <vdbhair/Quantile.h>
#include <vdbhair/field/HeadCollision.h>
#include <vdbhair/field/HeadObstacle.h>
#include <vdbhair/strands/Measures.h>

#include <openvdb/math/Mat3.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <vector>

namespace vdbhair {

namespace {

constexpr double kCrownElevationDeg = 50.0;
constexpr double kFringeAngleDeg = 60.0, kBackAngleDeg = 120.0;
constexpr double kLiftHeight = 0.1;     ///< head radii above the root
constexpr double kFlowReach = 0.5;      ///< head radii along a strand: the direction it leaves its root in
/// Curl amplitude at one scale in head radii, whatever a strand's length: samples at most every
/// 1/25 head radius (at least every 1/200), the centre line their local quadratic fit with
/// Gaussian weights of σ = 0.25 head radii (curlCentreLine()), strands cut into pieces of about a
/// head radius, each at least 0.6 long. A quadratic follows a strand's overall bend: hair lying on
/// a head of radius 1 reads 0.001 (a Gaussian's own line, σ 0.15, cut across the bend and read it
/// as 0.010, a third of Curly_100's curls; Ruby's short hair, which has none, read 0.016). Curls
/// keep what the Gaussian kept: a helix of period 0.25 head radii 0.96 of its radius, 0.5 0.79,
/// 0.7 (Curly_100's) 0.49, 1.0 0.23 (on a piece of 1 head radius; a shorter piece reads a curl
/// of long period lower: pieces of one length compare alike).
constexpr double kCurlSpacing = 1.0 / 25.0, kCurlFinest = 1.0 / 200.0, kCurlSigma = 0.25, kCurlPiece = 1.0, kCurlShortest = 0.6;
constexpr std::size_t kCurlMaxSamples = 1 << 14;  ///< longer strands are sampled more coarsely

/// Per strand: length, lift, turning per length, its pieces' curl amplitudes (head radii: their
/// sum and count), vertices inside.
struct StrandFigures
{
    double length = 0.0, turning = 0.0, curlSum = 0.0;
    double flowDown = 0.0, flowAround = 0.0;  ///< the unit direction leaving the root (hasFlow)
    std::size_t curlPieces = 0;
    bool lifts = false, hasFlow = false;
    std::size_t inside = 0;
};

/// The centre line of @a n samples @a p, evenly spaced: at each sample the value at it of the
/// quadratic fitted by least squares to the samples within 3σ (@a sigma in samples), weighted by a
/// Gaussian (local quadratic regression). Where the window is whole this is one fixed kernel
/// (the odd moments vanish): w(x) (S4 - S2 x²) / (S0 S4 - S2²); near the ends, where it is cut,
/// the 3 × 3 normal equations are solved at each sample. A circle is followed to fourth order, a
/// curl much shorter than σ is averaged out.
void curlCentreLine(const Vec3d* p, std::size_t n, double sigma, Vec3d* out)
{
    const long last = long(n) - 1, r = std::max(1L, long(std::ceil(3.0 * sigma)));
    std::vector<double> w(std::size_t(r) + 1);
    for (long k = 0; k <= r; ++k) w[std::size_t(k)] = std::exp(-0.5 * double(k * k) / (sigma * sigma));
    const auto fit = [&](long i, long lo, long hi) {
        double m[5] = {0, 0, 0, 0, 0};
        Vec3d b0(0.0), b1(0.0), b2(0.0);
        for (long j = lo; j <= hi; ++j) {
            const double x = double(j - i), wx = w[std::size_t(std::abs(j - i))];
            const double x2 = x * x;
            m[0] += wx; m[1] += wx * x; m[2] += wx * x2; m[3] += wx * x2 * x; m[4] += wx * x2 * x2;
            b0 += p[j] * wx; b1 += p[j] * (wx * x); b2 += p[j] * (wx * x2);
        }
        // The intercept of [m0 m1 m2; m1 m2 m3; m2 m3 m4] (a, b, c) = (b0, b1, b2), by Cramer's rule
        // (a window of three or more samples has a positive determinant; fewer: the sample itself).
        const double c0 = m[2] * m[4] - m[3] * m[3], c1 = m[2] * m[3] - m[1] * m[4], c2 = m[1] * m[3] - m[2] * m[2];
        const double det = m[0] * c0 + m[1] * c1 + m[2] * c2;
        return hi - lo >= 2 && det > 1e-12 * m[0] * m[0] * m[4] ? (b0 * c0 + b1 * c1 + b2 * c2) / det : p[i];
    };
    if (2 * r > last) {
        for (long i = 0; i <= last; ++i) out[i] = fit(i, std::max(0L, i - r), std::min(last, i + r));
        return;
    }
    double s0 = w[0], s2 = 0.0, s4 = 0.0;
    for (long k = 1; k <= r; ++k) {
        const double x2 = double(k * k);
        s0 += 2.0 * w[std::size_t(k)];
        s2 += 2.0 * w[std::size_t(k)] * x2;
        s4 += 2.0 * w[std::size_t(k)] * x2 * x2;
    }
    std::vector<double> kernel(std::size_t(r) + 1);
    for (long k = 0; k <= r; ++k) kernel[std::size_t(k)] = w[std::size_t(k)] * (s4 - s2 * double(k * k)) / (s0 * s4 - s2 * s2);
    for (long i = 0; i <= last; ++i) {
        if (i < r || i > last - r) {
            out[i] = fit(i, std::max(0L, i - r), std::min(last, i + r));
            continue;
        }
        Vec3d sum = p[i] * kernel[0];
        for (long k = 1; k <= r; ++k) sum += (p[i - k] + p[i + k]) * kernel[std::size_t(k)];
        out[i] = sum;
    }
}

/// The curl amplitude of strand @a i of length @a length (world units): the strand cut into
/// pieces of about @a piece (at least one), each at least kCurlShortest long, and of each piece the RMS
/// distance from its own centre line (curlCentreLine(): a straight or evenly bent piece has
/// none); @a sum and @a count receive the pieces' amplitudes (head radii).
void strandCurl(const StrandSet& s, std::size_t i, double length, double radius, double piece, double& sum, std::size_t& count,
                std::vector<Vec3d>& pts, std::vector<Vec3d>& smooth)
{
    if (!(length >= kCurlShortest * radius)) return;
    const std::size_t b = s.offsets[i], e = s.offsets[i + 1];
    // At the strand's own vertex spacing within [1/200, 1/25] head radius: a curl tighter than
    // the coarse spacing would alias, and none is finer than the strand's vertices.
    const double own = length / double(std::max<std::size_t>(1, e - b - 1));
    const double spacing = std::clamp(own, kCurlFinest * radius, kCurlSpacing * radius);
    const std::size_t n = std::min(kCurlMaxSamples, std::size_t(length / spacing) + 2);
    pts.assign(n, Vec3d(0.0));
    const double step = length / double(n - 1);
    std::size_t k = b;
    double walked = 0.0;
    for (std::size_t j = 0; j < n; ++j) {
        const double target = std::min(length, step * double(j));
        while (k + 2 < e && walked + (Vec3d(s.positions[k + 1]) - Vec3d(s.positions[k])).length() < target) {
            walked += (Vec3d(s.positions[k + 1]) - Vec3d(s.positions[k])).length();
            ++k;
        }
        const Vec3d p0(s.positions[k]), p1(s.positions[k + 1]);
        const double seg = (p1 - p0).length();
        const double t = seg > 0.0 ? std::clamp((target - walked) / seg, 0.0, 1.0) : 0.0;
        pts[j] = p0 + t * (p1 - p0);
    }
    const std::size_t pieces = std::max<std::size_t>(1, std::size_t(std::llround(length / std::max(piece, 1e-30))));
    smooth.resize(n);
    for (std::size_t q = 0; q < pieces && q < n - 1; ++q) {
        const std::size_t lo = q * (n - 1) / pieces, hi = (q + 1) * (n - 1) / pieces;
        if (double(hi - lo) * step < kCurlShortest * radius) continue;
        curlCentreLine(pts.data() + lo, hi - lo + 1, kCurlSigma * radius / step, smooth.data());
        double rms = 0.0;
        for (std::size_t j = lo; j <= hi; ++j) rms += (pts[j] - smooth[j - lo]).lengthSqr();
        sum += std::sqrt(rms / double(hi - lo + 1)) / radius;
        ++count;
    }
}

/// The flow of a strand (StyleRegions.h): the direction from its root to the point @a reach along
/// it (its tip when shorter), in the head's tangent plane at the root, as parts down the head and
/// around it; false where the root is on the up axis or the direction is normal to the head.
bool strandFlow(const StrandSet& s, std::size_t i, const RegionFrame& f, double reach, double& down, double& around)
{
    const std::size_t b = s.offsets[i], e = s.offsets[i + 1];
    const Vec3d root(s.positions[b]);
    Vec3d at(s.positions[e - 1]);
    double walked = 0.0;
    for (std::size_t k = b; k + 1 < e; ++k) {
        const Vec3d p0(s.positions[k]), p1(s.positions[k + 1]);
        const double seg = (p1 - p0).length();
        if (walked + seg >= reach) {
            at = p0 + (seg > 0.0 ? (reach - walked) / seg : 0.0) * (p1 - p0);
            break;
        }
        walked += seg;
    }
    const Vec3d normal = root - f.center;
    const Vec3d aroundAxis = f.up.cross(normal);
    if (!(normal.length() > 0.0) || !(aroundAxis.length() > 1e-9 * normal.length())) return false;
    const Vec3d n = normal.unit(), a = aroundAxis.unit(), m = a.cross(n);  // m: down the meridian
    Vec3d v = at - root;
    const double reached = v.length();
    v -= v.dot(n) * n;
    const double len = v.length();
    if (!(len > 1e-3 * reached)) return false;  // straight out of the head (within float rounding)
    down = v.dot(m) / len;
    around = v.dot(a) / len;
    return true;
}

StrandFigures strandFigures(const StrandSet& s, std::size_t i, const RegionFrame& f, HeadObstacle::Probe* head, double tolerance,
                            std::vector<Vec3d>& pts, std::vector<Vec3d>& smooth)
{
    StrandFigures out;
    const std::size_t b = s.offsets[i], e = s.offsets[i + 1];
    const Vec3d root(s.positions[b]);
    double highest = 0.0, length = 0.0, turning = 0.0;
    for (std::size_t k = b; k < e; ++k) {
        const Vec3d p(s.positions[k]);
        highest = std::max(highest, (p - root).dot(f.up));
        if (head && head->distance(p) < -tolerance) ++out.inside;
        if (k + 1 < e) length += (Vec3d(s.positions[k + 1]) - p).length();
        if (k > b && k + 1 < e) {
            Vec3d a = p - Vec3d(s.positions[k - 1]), c = Vec3d(s.positions[k + 1]) - p;
            const double la = a.length(), lc = c.length();
            if (la > 0.0 && lc > 0.0) turning += std::acos(std::clamp(a.dot(c) / (la * lc), -1.0, 1.0));
        }
    }
    out.length = length / f.radius;
    out.lifts = highest > kLiftHeight * f.radius;
    out.turning = length > 0.0 ? turning / out.length : 0.0;
    strandCurl(s, i, length, f.radius, kCurlPiece * f.radius, out.curlSum, out.curlPieces, pts, smooth);
    out.hasFlow = strandFlow(s, i, f, kFlowReach * f.radius, out.flowDown, out.flowAround);
    return out;
}

} // namespace

const char* styleRegionName(StyleRegion r)
{
    switch (r) {
    case StyleRegion::Crown: return "crown";
    case StyleRegion::Fringe: return "fringe";
    case StyleRegion::Sides: return "sides";
    case StyleRegion::Back: return "back";
    }
    return "?";
}

RegionFrame regionFrameFromRoots(const StrandSet& strands, const Vec3d& center, const Vec3d& up, double radius)
{
    RegionFrame f;
    f.center = center;
    f.up = up.length() > 0.0 ? up.unit() : Vec3d(0.0, 1.0, 0.0);
    f.radius = radius > 0.0 ? radius : 1.0;
    // Two axes perpendicular to up: azimuth 0 along e1.
    Vec3d e1 = std::abs(f.up.z()) < 0.9 ? Vec3d(0.0, 0.0, 1.0) : Vec3d(0.0, -1.0, 0.0);
    e1 = (e1 - e1.dot(f.up) * f.up).unit();
    const Vec3d e2 = f.up.cross(e1);
    // The hairline's height per azimuth: the lowest root elevation below the crown in each of kBins sectors (a
    // sector without roots says nothing). The forehead's is the highest of a head (the nape's the
    // lowest, the ears' between), whatever the parting or the sweep.
    constexpr int kBins = 24;
    std::array<double, kBins> lowest;
    lowest.fill(std::numeric_limits<double>::infinity());  // no root in the sector: no evidence
    for (std::size_t i = 0; i < strands.numStrands(); ++i) {
        const Vec3d d = Vec3d(strands.root(i)) - center;
        const double len = d.length();
        if (!(len > 0.0)) continue;
        const double elevation = std::asin(std::clamp(d.dot(f.up) / len, -1.0, 1.0)) * 180.0 / M_PI;
        if (elevation > kCrownElevationDeg) continue;  // the crown says nothing of the hairline
        const double azimuth = std::atan2(d.dot(e2), d.dot(e1));
        const int bin = (int(std::floor((azimuth + M_PI) / (2.0 * M_PI) * kBins)) % kBins + kBins) % kBins;
        lowest[std::size_t(bin)] = std::min(lowest[std::size_t(bin)], elevation);
    }
    // h(a) ~ c0 + c1 cos a + s1 sin a by least squares over the sectors with roots: the front is
    // where the first harmonic peaks, atan2(s1, c1).
    openvdb::math::Mat3d normal = openvdb::math::Mat3d::zero();
    openvdb::math::Vec3d rhs(0.0);
    int sectors = 0;
    for (int b = 0; b < kBins; ++b) {
        if (!std::isfinite(lowest[std::size_t(b)])) continue;
        const double a = (double(b) + 0.5) / kBins * 2.0 * M_PI - M_PI;
        const openvdb::math::Vec3d row(1.0, std::cos(a), std::sin(a));
        for (int i = 0; i < 3; ++i) {
            rhs[i] += row[i] * lowest[std::size_t(b)];
            for (int j = 0; j < 3; ++j) normal(i, j) += row[i] * row[j];
        }
        ++sectors;
    }
    double azimuth = 0.0;  // too few sectors to tell: azimuth 0 (e1)
    if (sectors >= 3 && std::abs(normal.det()) > 1e-9) {
        const openvdb::math::Vec3d c = normal.inverse() * rhs;
        if (std::hypot(c[1], c[2]) > 0.0) azimuth = std::atan2(c[2], c[1]);
    }
    f.front = (std::cos(azimuth) * e1 + std::sin(azimuth) * e2).unit();
    return f;
}

StyleRegion regionOf(const RegionFrame& f, const Vec3d& root)
{
    const Vec3d d = root - f.center;
    const double len = d.length();
    if (!(len > 0.0)) return StyleRegion::Crown;
    const double elevation = std::asin(std::clamp(d.dot(f.up) / len, -1.0, 1.0)) * 180.0 / M_PI;
    if (elevation > kCrownElevationDeg) return StyleRegion::Crown;
    Vec3d h = d - d.dot(f.up) * f.up;
    if (!(h.length() > 0.0)) return StyleRegion::Sides;
    const double angle = std::acos(std::clamp(h.unit().dot(f.front), -1.0, 1.0)) * 180.0 / M_PI;
    if (angle < kFringeAngleDeg) return StyleRegion::Fringe;
    if (angle > kBackAngleDeg) return StyleRegion::Back;
    return StyleRegion::Sides;
}

StyleRegions measureStyleRegions(const StrandSet& strands, const RegionFrame& frame, const HeadObstacle* head, bool threaded)
{
    const std::size_t nS = strands.numStrands();
    std::vector<StrandFigures> per(nS);
    std::vector<StyleRegion> region(nS);
    const bool withHead = head && !head->empty();
    // Inside: deeper than a level set's half voxel (refine --head's rule), or than rounding on a sphere.
    const double tolerance = withHead ? std::max(headTolerance(*head), 1e-6 * frame.radius) : 0.0;
    forEachRange(nS, threaded, 256, [&](const tbb::blocked_range<std::size_t>& range) {
        std::vector<Vec3d> pts, smooth;
        std::optional<HeadObstacle::Probe> probe;
        if (withHead) probe.emplace(*head);
        for (std::size_t i = range.begin(); i != range.end(); ++i) {
            region[i] = regionOf(frame, Vec3d(strands.root(i)));
            per[i] = strandFigures(strands, i, frame, probe ? &*probe : nullptr, tolerance, pts, smooth);
        }
    });
    StyleRegions out;
    out.frame = frame;
    for (int r = 0; r < kStyleRegions; ++r) {
        RegionFigures& g = out.regions[std::size_t(r)];
        std::vector<double> lengths;
        std::size_t lifts = 0, inside = 0, vertices = 0;
        double turning = 0.0, curl = 0.0, down = 0.0, around = 0.0;
        std::size_t curled = 0;   // pieces of strands long enough for a curl amplitude
        std::size_t flowing = 0;  // strands with a flow
        for (std::size_t i = 0; i < nS; ++i) {
            if (int(region[i]) != r) continue;
            lengths.push_back(per[i].length);
            lifts += per[i].lifts;
            turning += per[i].turning;
            curl += per[i].curlSum;
            curled += per[i].curlPieces;
            inside += per[i].inside;
            if (per[i].hasFlow) {
                down += per[i].flowDown;
                around += per[i].flowAround;
                ++flowing;
            }
            vertices += strands.size(i);
        }
        g.strands = lengths.size();
        g.share = nS ? double(g.strands) / double(nS) : 0.0;
        if (g.strands == 0) continue;
        g.lengthP25 = quantile(lengths, 0.25);
        g.lengthP50 = quantile(lengths, 0.5);
        g.lengthP75 = quantile(lengths, 0.75);
        g.lift = double(lifts) / double(g.strands);
        g.turning = turning / double(g.strands);
        g.curlAmplitude = curled ? curl / double(curled) : 0.0;
        g.flowDown = flowing ? down / double(flowing) : 0.0;
        g.flowAround = flowing ? around / double(flowing) : 0.0;
        g.insideHead = withHead ? double(inside) / double(vertices) : -1.0;
    }
    return out;
}

double meanCurlAmplitude(const StrandSet& strands, double radius, double piece)
{
    double sum = 0.0;
    std::size_t count = 0;
    std::vector<Vec3d> pts, smooth;
    for (std::size_t i = 0; i < strands.numStrands(); ++i)
        strandCurl(strands, i, polylineLength(strands.data(i), strands.size(i)), radius, (piece > 0.0 ? piece : kCurlPiece) * radius, sum, count, pts, smooth);
    return count ? sum / double(count) : 0.0;
}

double medianCurlPiece(const StrandSet& strands, double radius)
{
    std::vector<double> lengths;
    for (std::size_t i = 0; i < strands.numStrands(); ++i) {
        const double l = polylineLength(strands.data(i), strands.size(i)) / radius;
        if (l >= kCurlShortest) lengths.push_back(l);
    }
    return lengths.empty() ? kCurlPiece : quantile(lengths, 0.5);
}

nlohmann::json toJson(const StyleRegions& example, const StyleRegions& output)
{
    const RegionFrame& f = example.frame;
    nlohmann::json j;
    j["frame"] = {{"center", {f.center.x(), f.center.y(), f.center.z()}}, {"up", {f.up.x(), f.up.y(), f.up.z()}},
                  {"front", {f.front.x(), f.front.y(), f.front.z()}}, {"radius", f.radius}};
    for (int r = 0; r < kStyleRegions; ++r) {
        const RegionFigures &a = example.regions[std::size_t(r)], &b = output.regions[std::size_t(r)];
        auto pair = [&](double x, double y, bool hasX, bool hasY) {
            return nlohmann::json{{"example", hasX ? nlohmann::json(x) : nlohmann::json(nullptr)},
                                  {"output", hasY ? nlohmann::json(y) : nlohmann::json(nullptr)}};
        };
        const bool ha = a.strands > 0, hb = b.strands > 0;
        nlohmann::json g;
        g["strands"] = {{"example", a.strands}, {"output", b.strands}};
        g["share"] = pair(a.share, b.share, true, true);
        g["length_p25"] = pair(a.lengthP25, b.lengthP25, ha, hb);
        g["length_p50"] = pair(a.lengthP50, b.lengthP50, ha, hb);
        g["length_p75"] = pair(a.lengthP75, b.lengthP75, ha, hb);
        g["lift"] = pair(a.lift, b.lift, ha, hb);
        g["turning"] = pair(a.turning, b.turning, ha, hb);
        g["curl_amplitude"] = pair(a.curlAmplitude, b.curlAmplitude, ha, hb);
        const auto flow = [](const RegionFigures& x) { return nlohmann::json::array({x.flowDown, x.flowAround}); };
        g["flow"] = {{"example", ha ? flow(a) : nlohmann::json(nullptr)}, {"output", hb ? flow(b) : nlohmann::json(nullptr)}};
        g["flow_difference"] = ha && hb ? nlohmann::json(std::hypot(a.flowDown - b.flowDown, a.flowAround - b.flowAround)) : nlohmann::json(nullptr);
        g["inside_head"] = pair(a.insideHead, b.insideHead, ha && a.insideHead >= 0.0, hb && b.insideHead >= 0.0);
        j[styleRegionName(StyleRegion(r))] = g;
    }
    return j;
}

std::string summaryLines(const StyleRegions& example, const StyleRegions& output, const std::string& indent)
{
    std::string out;
    char buf[512];
    for (int r = 0; r < kStyleRegions; ++r) {
        const RegionFigures &a = example.regions[std::size_t(r)], &b = output.regions[std::size_t(r)];
        std::snprintf(buf, sizeof buf,
                      "%s%-6s %4.1f %% of strands (example %4.1f %%), length p25/p50/p75 %.2f/%.2f/%.2f (%.2f/%.2f/%.2f), "
                      "lift %.0f %% (%.0f %%), turning %.2f (%.2f), curl %.3f (%.3f), flow down/around %.2f/%.2f (%.2f/%.2f)",
                      indent.c_str(), styleRegionName(StyleRegion(r)), 100.0 * b.share, 100.0 * a.share, b.lengthP25, b.lengthP50, b.lengthP75,
                      a.lengthP25, a.lengthP50, a.lengthP75, 100.0 * b.lift, 100.0 * a.lift, b.turning, a.turning, b.curlAmplitude, a.curlAmplitude,
                      b.flowDown, b.flowAround, a.flowDown, a.flowAround);
        out += buf;
        if (a.insideHead >= 0.0 && b.insideHead >= 0.0) {
            std::snprintf(buf, sizeof buf, ", inside the head %.1f %% (%.1f %%)", 100.0 * b.insideHead, 100.0 * a.insideHead);
            out += buf;
        }
        out += "\n";
    }
    return out;
}

nlohmann::json compareStyleRegions(const StrandSet& example, const StrandSet& output, const Vec3d& center, const Vec3d& up, double radius,
                                   const HeadObstacle* head, std::string* text, const Vec3d& front)
{
    RegionFrame frame = regionFrameFromRoots(example, center, up, radius);
    const Vec3d given = front - front.dot(frame.up) * frame.up;
    if (given.length() > 1e-9) frame.front = given.unit();
    const StyleRegions a = measureStyleRegions(example, frame, head), b = measureStyleRegions(output, frame, head);
    if (text) *text = summaryLines(a, b, "    ");
    return toJson(a, b);
}

} // namespace vdbhair
