#include "DetailEdges.h"

#include <vdbhair/strands/Frames.h>
#include <vdbhair/strands/Resample.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>

namespace vdbhair {
namespace detail {

namespace {

/// Edges whose angle has a cosine within this of 1 (about 0.06 degrees) are collinear (strandEdges()):
/// a coarse polyline resampled to n_s (Curly_100 has 15-19 vertices a strand) is a run of collinear
/// edges between its corners. Each edge held in the carrier's frame at its own middle, a run came
/// out bent wherever the output carrier turned otherwise than the strand's own, every edge by a
/// little, and the bends added up: Curly_100 synthesized had strands with 2.6 times the turning of
/// the strand they copied (7.2 rad against 2.7).
constexpr double kCollinearCos = 5e-7;

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

} // namespace

Carrier::Carrier(const std::vector<Vec3d>& p, double sigma, const Vec3f& reference)
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

void Carrier::frameAt(double s, Vec3d axes[3]) const
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

} // namespace detail
} // namespace vdbhair
