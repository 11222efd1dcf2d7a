#include "DetailEdges.h"

#include <vdbhair/Rotation.h>
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

/// The least mean cosine between a curly strand's edges and its centre that strandCurl() takes:
/// edges leaning further off (about 70 degrees) make a coil that hardly moves along the centre.
constexpr double kMinCurlRho = 0.35;

/// @a v turned by the shortest rotation taking unit @a from onto x̂ (half a turn about a
/// perpendicular of @a from when it is -x̂).
Vec3d rotateOntoX(const Vec3d& from, const Vec3d& v)
{
    return rotateOnto(from, Vec3d(1.0, 0.0, 0.0), v, Vec3d(perpendicularTo(Vec3f(from))).unitSafe());
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
        for (Vec3d& e : loop) e = rotateOntoX(net.unitSafe(), e);
    // The twist about x̂ that takes the edges before the loop's start (as turned) onto the strand's last edges.
    double sn = 0.0, cs = 0.0;
    if (a > 0) {
        const Vec3d before = net.length() > 1e-30 ? rotateOntoX(net.unitSafe(), d[a - 1]) : d[a - 1];
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

void Carrier::locate(double s, std::size_t& j, double& u, std::size_t* hint) const
{
    j = 0;
    u = 0.0;
    if (s >= arc.back()) {
        j = arc.size() - 1;
    } else if (s > 0.0) {
        if (hint) {
            // The last vertex at or before s, walked to from the last one found (a strand laid
            // edge by edge moves along its carrier a little at a time).
            j = std::min(*hint, arc.size() - 2);
            while (j + 1 < arc.size() && arc[j + 1] <= s) ++j;
            while (j > 0 && arc[j] > s) --j;
        } else {
            j = std::size_t(std::upper_bound(arc.begin(), arc.end(), s) - arc.begin()) - 1;
        }
        const double span = arc[j + 1] - arc[j];
        u = span > 0.0 ? (s - arc[j]) / span : 0.0;
    }
    if (hint) *hint = j;
}

Vec3d Carrier::pointAt(double s, std::size_t* hint) const
{
    std::size_t j = 0;
    double u = 0.0;
    locate(s, j, u, hint);
    const Vec3d p(points[j]);
    return u > 0.0 && j + 1 < points.size() ? p + (Vec3d(points[j + 1]) - p) * u : p;
}

void Carrier::frameAt(double s, Vec3d axes[3], std::size_t* hint) const
{
    std::size_t j = 0;
    double u = 0.0;
    locate(s, j, u, hint);
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

Curl wispCurl(const std::vector<std::vector<Vec3d>>& strands, const Carrier& centre, double sigma)
{
    double length = 0.0, along = 0.0, turning = 0.0, mostTurning = 0.0, twist = 0.0, twistScale = 0.0;
    std::vector<Vec3d> strand;
    for (const std::vector<Vec3d>& raw : strands) {
        strand.resize(raw.size());
        smoothPolyline(raw.data(), raw.size(), sigma, strand.data());
        Vec3d prevUnit(0.0), prevPerp(0.0);
        double turned = 0.0;
        for (std::size_t k = 0; k + 1 < strand.size() && k + 1 < centre.frames.size(); ++k) {
            const Vec3d e = strand[k + 1] - strand[k];
            const double l = e.length();
            if (!(l > 0.0)) continue;
            const Vec3d u = e / l, t = (Vec3d(centre.frames[k].t) + Vec3d(centre.frames[k + 1].t)).unitSafe();
            const Vec3d perp = u - t * u.dot(t);
            length += l;
            along += e.dot(t);
            if (prevUnit.lengthSqr() > 0.0) {
                turned += std::acos(std::clamp(prevUnit.dot(u), -1.0, 1.0));
                twist += prevPerp.cross(perp).dot(t);
                twistScale += prevPerp.length() * perp.length();
            }
            prevUnit = u;
            prevPerp = perp;
        }
        turning += turned;
        mostTurning = std::max(mostTurning, turned);
    }
    Curl curl;
    if (!(length > 0.0) || mostTurning < M_PI) return curl;
    curl.kappa = turning / length;
    curl.rho = std::clamp(along / length, kMinCurlRho, 1.0);
    curl.handed = twist < -0.05 * twistScale ? -1.0 : 1.0;
    const double sine = std::sqrt(1.0 - curl.rho * curl.rho);
    if (sine > 1e-3) curl.period = 2.0 * M_PI * sine / curl.kappa;
    return curl;
}

namespace {

/// Lays edges, given in the frame of a carrier at their place along it, one after another.
struct EdgeLayer
{
    const Carrier& carrier;
    const double lambda, target;
    std::vector<Vec3d> out;
    double progress = 0.0;
    std::size_t hint = 0;  ///< where along the carrier the last frame was found

    bool done() const { return progress >= target * (1.0 - 1e-9); }

    /// Lay @a local (in the carrier's frame at @a shift past the progress, or at the edge's middle
    /// when NaN), moving on @a step along the carrier; true when the target is reached (the edge
    /// then cut there).
    bool lay(const Vec3d& local, double step, double shift)
    {
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
        carrier.frameAt(std::isnan(shift) ? progress + 0.5 * step : progress + shift * lambda, axes, &hint);
        out.push_back(out.back() + axes[0] * e.x() + axes[1] * e.y() + axes[2] * e.z());
        progress += step;
        return last;
    }

    /// Past the strand's end, its loop (strandLoop()) repeats, each time turned by one more twist.
    void repeatLoop(const std::vector<Vec3d>& d);

    /// Past the strand's end, the helix of @a curl (steps of @a step, unscaled): from the strand's
    /// last direction, its lean along the carrier eased to the helix's over a turn.
    void continueHelix(const Curl& curl, double step);
};

/// (A cap on the vertices laid past the strand's end: targets are at most a few dozen strand lengths, kMaxOutputVertices.)
constexpr std::size_t kMaxLaid = std::size_t(1) << 16;

void EdgeLayer::repeatLoop(const std::vector<Vec3d>& d)
{
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
            for (Vec3d& e : loop) e = rotateOntoX(net.unitSafe(), e);
        twist = 0.0;
        loopStep = stepOf(loop, arc);
        if (!(loopStep > 0.0)) return;
    }
    for (int r = 1; progress < target && out.size() < kMaxLaid; ++r) {
        const double c = std::cos(twist * r), sn = std::sin(twist * r);
        for (const Vec3d& e : loop)
            if (lay(Vec3d(e.x(), c * e.y() - sn * e.z(), sn * e.y() + c * e.z()), std::max(0.0, e.x()), std::numeric_limits<double>::quiet_NaN())) return;
    }
}

void EdgeLayer::continueHelix(const Curl& curl, double step)
{
    if (out.size() < 2 || !(step > 0.0)) return;
    // The strand's last edge in the carrier's frame where it ended.
    Vec3d axes[3];
    carrier.frameAt(progress, axes);
    const Vec3d last = (out.back() - out[out.size() - 2]).unitSafe();
    const double x0 = std::clamp(last.dot(axes[0]), -1.0, 1.0);
    double phase = std::atan2(last.dot(axes[2]), last.dot(axes[1]));
    // The perpendicular direction turns at κ / sin(lean) per length (a helix of curvature κ).
    const double sine = std::sqrt(1.0 - curl.rho * curl.rho), rate = curl.kappa / sine, ease = 2.0 * M_PI / rate;
    const double radius = sine * sine / curl.kappa, pull = std::min(1.0, step / (0.5 * ease));
    double s = 0.0;
    while (progress < target && out.size() < kMaxLaid) {
        s += step;
        phase += curl.handed * rate * step;
        const double w = std::min(1.0, s / ease), x = x0 + (curl.rho - x0) * w * w * (3.0 - 2.0 * w);
        const double p = std::sqrt(std::max(0.0, 1.0 - x * x));
        Vec3d local = Vec3d(x, p * std::cos(phase), p * std::sin(phase)) * step;
        // Steered onto the helix about the carrier itself: where the helix would be at this
        // phase (radius r, a quarter turn behind its tangent) less where the strand is, closed
        // over about half a turn, so that a wisp's strands, which share their source's last
        // direction, do not all wind about an axis beside the wisp's.
        Vec3d axes[3];
        carrier.frameAt(progress, axes, &hint);
        const Vec3d offset = out.back() - carrier.pointAt(progress, &hint);
        const double wantN = curl.handed * radius * std::sin(phase), wantB = -curl.handed * radius * std::cos(phase);
        local += Vec3d(0.0, wantN - offset.dot(axes[1]), wantB - offset.dot(axes[2])) * pull;
        if (lay(local / lambda, local.x() / lambda, std::numeric_limits<double>::quiet_NaN())) return;
    }
}

} // namespace

std::vector<Vec3d> layEdges(const std::vector<Vec3d>& d, const std::vector<double>& advance, const std::vector<double>& frameShift,
                            double lambda, const Carrier& carrier, const Vec3d& root, double target, const Curl& curl)
{
    EdgeLayer layer{carrier, lambda, target, {root}};
    layer.out.reserve(d.size() + 1);
    double arc = 0.0;
    for (std::size_t k = 0; k < d.size(); ++k) {
        arc += d[k].length();
        if (layer.lay(d[k], advance[k], frameShift[k])) return layer.out;
    }
    if (layer.done()) return layer.out;
    // The helix in steps of the strand's edges, or of 1/32 of a turn where they are finer.
    if (arc < 1.5 * curl.period) layer.continueHelix(curl, std::max(lambda * arc / double(std::max<std::size_t>(1, d.size())), curl.period / 32.0));
    else layer.repeatLoop(d);
    return layer.out;
}

} // namespace detail
} // namespace vdbhair
