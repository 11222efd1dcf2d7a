#include "Helicoid.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/helicoid/FastMath.h>
#include <vdbhair/helicoid/AnalyticHelicoidSampler.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace vdbhair {

FrameD FrameD::fromTangentNormal(const Vec3d& t, const Vec3d& n)
{
    const double lt = t.length();
    if (!(lt > 0.0) || !std::isfinite(lt)) throw ValueError("frame tangent must be a non-zero finite vector");
    FrameD f;
    f.t = t / lt;
    const Vec3d w = n - f.t * n.dot(f.t);
    const double lw = w.length();
    if (!(lw > 1e-9 * std::max(1.0, n.length()))) throw ValueError("frame normal must not be parallel to the tangent");
    f.n = w / lw;
    f.b = f.t.cross(f.n);
    return f;
}

FrameD FrameD::rolled(double angle) const
{
    if (angle == 0.0) return *this;
    const double c = std::cos(angle), s = std::sin(angle);
    FrameD f;
    f.t = t;
    f.n = c * n + s * b;
    f.b = t.cross(f.n);
    return f;
}

FrameD Helicoid::frameFromTheta(double th) const
{
    const double phi = k.alpha * th;
    double ct, st, cp = 1.0, sp = 0.0;
    fastmath::sinCos(th, st, ct);
    if (phi != 0.0) fastmath::sinCos(phi, sp, cp);
    FrameD f;
    f.t = (cp * ct) * q.t + (cp * st) * q.n + sp * q.b;
    f.n = (-st) * q.t + ct * q.n;
    f.b = (-sp * ct) * q.t + (-sp * st) * q.n + cp * q.b;
    return f;
}

double traceClearance(const HelicoidTrace& trace, double step)
{
    double nearest = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < trace.pieces.size() && i < trace.joints.size(); ++i) {
        const std::size_t end = i + 1 < trace.joints.size() ? trace.joints[i + 1] + 1 : trace.points.size();
        for (std::size_t j = trace.joints[i]; j < end && j < trace.points.size(); ++j) {
            nearest = std::min(nearest, trace.pieces[i].axisDistance(trace.points[j]));
        }
    }
    return nearest / step;
}

namespace {

// The lane kernels come in an AVX2 and a baseline clone. GCC inlines the lane math into them only
// when told to (flatten; see HelicoidLanes); clang does it by itself and refuses flatten with
// target_clones.
#if defined(__clang__)
#define VDBHAIR_LANE_KERNEL __attribute__((target_clones("avx2", "default")))
#else
#define VDBHAIR_LANE_KERNEL __attribute__((target_clones("avx2", "default"), flatten))
#endif

constexpr int kLanes = 8;

/// @brief kLanes positions moved one forward-Euler step (Eq. 3) through one helicoid, then theta
/// (unwrapped), the frame of Eq. 2 and the next tangent there. Structure of arrays with a fixed
/// trip count and branchless math, so the compiler vectorizes it (with AVX2 where the processor
/// has it: the clones differ only in vector width, not in results, since none contracts to FMA).
struct EulerLanes
{
    double px[kLanes], py[kLanes], pz[kLanes];
    double tx[kLanes], ty[kLanes], tz[kLanes];     // E_T at the current point
    double nx[kLanes], ny[kLanes], nz[kLanes];
    double bx[kLanes], by[kLanes], bz[kLanes];
    double th[kLanes];

    VDBHAIR_LANE_KERNEL  // flatten: see HelicoidLanes
    void step(const Helicoid& h, double hstep)
    {
        const double qtx = h.q.t.x(), qty = h.q.t.y(), qtz = h.q.t.z();
        const double qnx = h.q.n.x(), qny = h.q.n.y(), qnz = h.q.n.z();
        const double qbx = h.q.b.x(), qby = h.q.b.y(), qbz = h.q.b.z();
        const double ox = h.p0.x(), oy = h.p0.y(), oz = h.p0.z();
        const double kT = h.k.kT, kN = h.k.kN, kB = h.k.kB, alpha = h.k.alpha;
        for (int l = 0; l < kLanes; ++l) {
            px[l] += hstep * tx[l];
            py[l] += hstep * ty[l];
            pz[l] += hstep * tz[l];
            const double dx = px[l] - ox, dy = py[l] - oy, dz = pz[l] - oz;
            const double y1 = dx * qtx + dy * qty + dz * qtz;
            const double y2 = dx * qnx + dy * qny + dz * qnz;
            const double y3 = dx * qbx + dy * qby + dz * qbz;
            double st, ct, sp, cp;
            laneAngles(y1, y2, y3, kT, kN, kB, alpha, th[l], st, ct, sp, cp);
            const double a = cp * ct, b = cp * st, e = -sp * ct, f = -sp * st;
            tx[l] = a * qtx + b * qnx + sp * qbx;
            ty[l] = a * qty + b * qny + sp * qby;
            tz[l] = a * qtz + b * qnz + sp * qbz;
            nx[l] = -st * qtx + ct * qnx;
            ny[l] = -st * qty + ct * qny;
            nz[l] = -st * qtz + ct * qnz;
            bx[l] = e * qtx + f * qnx + cp * qbx;
            by[l] = e * qty + f * qny + cp * qby;
            bz[l] = e * qtz + f * qnz + cp * qbz;
        }
    }
    void set(int l, const Vec3d& p, const FrameD& fr, double theta)
    {
        px[l] = p.x(); py[l] = p.y(); pz[l] = p.z();
        tx[l] = fr.t.x(); ty[l] = fr.t.y(); tz[l] = fr.t.z();
        nx[l] = fr.n.x(); ny[l] = fr.n.y(); nz[l] = fr.n.z();
        bx[l] = fr.b.x(); by[l] = fr.b.y(); bz[l] = fr.b.z();
        th[l] = theta;
    }
    Vec3d point(int l) const { return Vec3d(px[l], py[l], pz[l]); }
    FrameD frame(int l) const
    {
        return FrameD{Vec3d(tx[l], ty[l], tz[l]), Vec3d(nx[l], ny[l], nz[l]), Vec3d(bx[l], by[l], bz[l])};
    }
};

/// @brief kLanes positions moved one step, each through its own helicoid and by its own step, with
/// forward Euler (Eq. 3) or classical RK4: the lane kernel for hairs that share nothing
/// (interpolated hair). Each stage is Helicoid::tangent() with the branchless forms of the same
/// polynomials, unwrapped against theta at the step's start as AnalyticHelicoidSampler does, and
/// the stages combine in StreamlineIntegrator's order (tests hold the lanes to tracePHelicoid()).
struct HelicoidLanes
{
    double px[kLanes], py[kLanes], pz[kLanes];
    double tx[kLanes], ty[kLanes], tz[kLanes];  // E_T at the current point
    double th[kLanes];                          // theta there (unwrapped)
    double hstep[kLanes];
    // Each lane's helicoid: Q's columns, p0, k.
    double qtx[kLanes], qty[kLanes], qtz[kLanes], qnx[kLanes], qny[kLanes], qnz[kLanes], qbx[kLanes], qby[kLanes], qbz[kLanes];
    double ox[kLanes], oy[kLanes], oz[kLanes];
    double kT[kLanes], kN[kLanes], kB[kLanes], alpha[kLanes];

    /// E_T of lane @a l's helicoid at (x, y, z); @a t is unwrapped against its value on entry.
    inline void tangent(int l, double x, double y, double z, double& t, double& ex, double& ey, double& ez) const
    {
        const double dx = x - ox[l], dy = y - oy[l], dz = z - oz[l];
        const double y1 = dx * qtx[l] + dy * qty[l] + dz * qtz[l];
        const double y2 = dx * qnx[l] + dy * qny[l] + dz * qnz[l];
        const double y3 = dx * qbx[l] + dy * qby[l] + dz * qbz[l];
        double st, ct, sp, cp;
        laneAngles(y1, y2, y3, kT[l], kN[l], kB[l], alpha[l], t, st, ct, sp, cp);
        const double u = cp * ct, v = cp * st;
        ex = u * qtx[l] + v * qnx[l] + sp * qbx[l];
        ey = u * qty[l] + v * qny[l] + sp * qby[l];
        ez = u * qtz[l] + v * qnz[l] + sp * qbz[l];
    }

    // flatten: the lane math must be inlined for the loops to vectorize (left to itself, the
    // compiler called sinCosLane out of line: a third of the kernel's instructions).
    VDBHAIR_LANE_KERNEL
    void stepEuler()
    {
        for (int l = 0; l < kLanes; ++l) {
            px[l] += hstep[l] * tx[l];
            py[l] += hstep[l] * ty[l];
            pz[l] += hstep[l] * tz[l];
            tangent(l, px[l], py[l], pz[l], th[l], tx[l], ty[l], tz[l]);
        }
    }

    VDBHAIR_LANE_KERNEL
    void stepRk4()
    {
        for (int l = 0; l < kLanes; ++l) {
            const double h = hstep[l], hh = 0.5 * h;
            double t2 = th[l], t3 = th[l], t4 = th[l];
            double k2x, k2y, k2z, k3x, k3y, k3z, k4x, k4y, k4z;
            tangent(l, px[l] + hh * tx[l], py[l] + hh * ty[l], pz[l] + hh * tz[l], t2, k2x, k2y, k2z);
            tangent(l, px[l] + hh * k2x, py[l] + hh * k2y, pz[l] + hh * k2z, t3, k3x, k3y, k3z);
            tangent(l, px[l] + h * k3x, py[l] + h * k3y, pz[l] + h * k3z, t4, k4x, k4y, k4z);
            const double h6 = h / 6.0;
            px[l] += h6 * (((tx[l] + 2.0 * k2x) + 2.0 * k3x) + k4x);
            py[l] += h6 * (((ty[l] + 2.0 * k2y) + 2.0 * k3y) + k4y);
            pz[l] += h6 * (((tz[l] + 2.0 * k2z) + 2.0 * k3z) + k4z);
            tangent(l, px[l], py[l], pz[l], th[l], tx[l], ty[l], tz[l]);
        }
    }

    /// Lane @a l on helicoid @a h at @a p, with theta @a theta and E_T @a t there.
    void set(int l, const Helicoid& h, const Vec3d& p, const Vec3d& t, double theta, double step)
    {
        px[l] = p.x(); py[l] = p.y(); pz[l] = p.z();
        tx[l] = t.x(); ty[l] = t.y(); tz[l] = t.z();
        th[l] = theta;
        hstep[l] = step;
        qtx[l] = h.q.t.x(); qty[l] = h.q.t.y(); qtz[l] = h.q.t.z();
        qnx[l] = h.q.n.x(); qny[l] = h.q.n.y(); qnz[l] = h.q.n.z();
        qbx[l] = h.q.b.x(); qby[l] = h.q.b.y(); qbz[l] = h.q.b.z();
        ox[l] = h.p0.x(); oy[l] = h.p0.y(); oz[l] = h.p0.z();
        kT[l] = h.k.kT; kN[l] = h.k.kN; kB[l] = h.k.kB; alpha[l] = h.k.alpha;
    }
    Vec3d point(int l) const { return Vec3d(px[l], py[l], pz[l]); }
};

/// Wisp strands through a shared helicoid field with forward Euler: tracePHelicoids' hot path.
void traceFieldEuler(const Vec3d* roots, std::size_t count, const std::vector<HelicoidPiece>& pieces, double step,
                     HelicoidTrace* outs, const std::vector<Helicoid>& field)
{
    std::size_t total = 1;
    for (const HelicoidPiece& pc : pieces) total += stepCount(pc.length, step);
    EulerLanes L;
    for (std::size_t first = 0; first < count; first += kLanes) {
        const int lanes = int(std::min<std::size_t>(kLanes, count - first));
        for (int l = 0; l < lanes; ++l) {
            HelicoidTrace& out = outs[first + std::size_t(l)];
            out.points.resize(total);
            out.frames.resize(total);
            out.arc.resize(total);
            out.pieces.assign(field.begin(), field.begin() + std::ptrdiff_t(pieces.size()));
            out.joints.clear();
            out.points[0] = roots[first + std::size_t(l)];
            out.arc[0] = 0.0;
        }
        // Idle lanes repeat lane 0: the loop always runs over all kLanes.
        for (int l = lanes; l < kLanes; ++l) L.set(l, roots[first], FrameD(), 0.0);
        std::size_t at = 0;  // index of the current point
        double s = 0.0;
        for (std::size_t i = 0; i < pieces.size(); ++i) {
            const Helicoid& h = field[i];
            for (int l = 0; l < lanes; ++l) {
                HelicoidTrace& out = outs[first + std::size_t(l)];
                out.joints.push_back(at);
                // theta along this piece, unwrapped from its value at the piece's first point;
                // the joint takes the new piece's frame.
                const double th = h.theta(out.points[at], 0.0);
                out.frames[at] = h.frameFromTheta(th);
                L.set(l, out.points[at], out.frames[at], th);
            }
            const std::size_t n = stepCount(pieces[i].length, step);
            for (std::size_t j = 0; j < n; ++j) {
                const double hstep = (j + 1 == n) ? pieces[i].length - double(n - 1) * step : step;
                s += hstep;
                L.step(h, hstep);
                ++at;
                for (int l = 0; l < lanes; ++l) {
                    HelicoidTrace& out = outs[first + std::size_t(l)];
                    out.points[at] = L.point(l);
                    out.frames[at] = L.frame(l);
                    out.arc[at] = s;
                }
            }
        }
    }
}

/// @brief One step of the streamline engine through helicoid @a h from @a p, whose E_T @a k1 and
/// theta @a theta the trace already has (Euler: Eq. 3, p + h E_T(p); RK4: every stage unwrapped
/// against theta at p). Not inlined on purpose: inlined into tracePHelicoids(), this TU's lane
/// math stopped being inlined into EulerLanes::step (perf: 3x its time) and wisps grew 1.5x
/// slower (measured, issue 12).
__attribute__((noinline)) Vec3d engineStep(const Helicoid& h, double theta, const Vec3d& p, const Vec3d& k1, double hstep,
                                           Integrator integrator)
{
    AnalyticHelicoidSampler sampler(h, theta);
    StreamlineIntegrator<AnalyticHelicoidSampler> step(sampler, integrator);
    Vec3d q;
    step.advanceFrom(p, k1, hstep, q);
    return q;
}

} // namespace

void tracePHelicoids(const Vec3d* roots, std::size_t count, const FrameD& frame, const std::vector<HelicoidPiece>& pieces,
                     double step, HelicoidIntegrator integrator, HelicoidTrace* outs, const std::vector<Helicoid>* field)
{
    if (field && integrator == HelicoidIntegrator::Euler) {
        traceFieldEuler(roots, count, pieces, step, outs, *field);
        return;
    }
    std::size_t total = 1;
    for (const HelicoidPiece& pc : pieces) total += stepCount(pc.length, step);
    for (std::size_t l = 0; l < count; ++l) {
        HelicoidTrace& out = outs[l];
        out.points.clear();
        out.frames.clear();
        out.arc.clear();
        out.pieces.clear();
        out.joints.clear();
        out.points.reserve(total);
        out.frames.reserve(total);
        out.arc.reserve(total);
    }
    constexpr std::size_t kMaxLanes = 8;
    double s = 0.0;
    // The strands advance in lockstep, kMaxLanes at a time: a step is a chain of dependent
    // operations (atan2, sin/cos, move), and independent strands let the processor overlap them.
    for (std::size_t first = 0; first < count; first += kMaxLanes) {
        const std::size_t lanes = std::min(kMaxLanes, count - first);
        Vec3d p[kMaxLanes];
        FrameD f[kMaxLanes], fr[kMaxLanes];
        double th[kMaxLanes];
        Helicoid h[kMaxLanes];
        for (std::size_t l = 0; l < lanes; ++l) {
            p[l] = roots[first + l];
            f[l] = frame;
        }
        s = 0.0;
        for (std::size_t i = 0; i < pieces.size(); ++i) {
            const HelicoidPiece& pc = pieces[i];
            for (std::size_t l = 0; l < lanes; ++l) {
                HelicoidTrace& out = outs[first + l];
                if (field) {
                    h[l] = (*field)[i];
                } else {
                    h[l].k = pc.k;
                    h[l].q = f[l].rolled(pc.roll);
                    h[l].p0 = p[l];
                }
                out.pieces.push_back(h[l]);
                out.joints.push_back(i == 0 ? 0 : out.points.size() - 1);
                // theta along this piece, unwrapped from its value at the piece's first point.
                th[l] = h[l].theta(p[l], 0.0);
                fr[l] = h[l].frameFromTheta(th[l]);
                if (i == 0) {
                    out.points.push_back(p[l]);
                    out.frames.push_back(fr[l]);
                    out.arc.push_back(0.0);
                } else {
                    out.frames.back() = fr[l];  // the joint takes the new piece's frame
                }
            }
            const std::size_t n = stepCount(pc.length, step);
            for (std::size_t j = 0; j < n; ++j) {
                const double hstep = (j + 1 == n) ? pc.length - double(n - 1) * step : step;
                s += hstep;
                for (std::size_t l = 0; l < lanes; ++l) {
                    p[l] = engineStep(h[l], th[l], p[l], fr[l].t, hstep, toIntegrator(integrator));
                    th[l] = h[l].theta(p[l], th[l]);
                    fr[l] = h[l].frameFromTheta(th[l]);
                    HelicoidTrace& out = outs[first + l];
                    out.points.push_back(p[l]);
                    out.frames.push_back(fr[l]);
                    out.arc.push_back(s);
                }
            }
            for (std::size_t l = 0; l < lanes; ++l) f[l] = fr[l];
        }
    }
}

void tracePHelicoidPoints(const PHelicoidRequest* strands, std::size_t count, HelicoidIntegrator integrator, Vec3f* const* out)
{
    HelicoidLanes L;
    const bool rk4 = integrator == HelicoidIntegrator::RK4;
    // Per lane: the strand, its piece, the steps left in it, the next point's index, and the
    // frame the next piece starts from (Eq. 2 at the piece's end).
    struct Lane
    {
        std::size_t strand = 0, piece = 0, stepsLeft = 0, steps = 0, at = 0;
        bool active = false;
        Helicoid h;
        double theta = 0.0;
    };
    Lane lanes[kLanes];
    // Start @a ln on piece @a i of its strand at point @a p with frame @a f (the previous piece's
    // frame at its end, or the root frame); false once the strand has no pieces left.
    const auto startPiece = [&](int ln, const Vec3d& p, FrameD f) {
        Lane& lane = lanes[ln];
        const PHelicoidRequest& r = strands[lane.strand];
        while (lane.piece < r.pieces->size()) {
            const HelicoidPiece& pc = (*r.pieces)[lane.piece];
            lane.h.k = pc.k;
            lane.h.q = f.rolled(pc.roll);
            lane.h.p0 = p;
            lane.theta = lane.h.theta(p, 0.0);
            lane.steps = stepCount(pc.length, r.step);
            lane.stepsLeft = lane.steps;
            if (lane.steps > 0) {
                L.set(ln, lane.h, p, lane.h.frameFromTheta(lane.theta).t, lane.theta, lane.steps == 1 ? pc.length : r.step);
                return true;
            }
            // A piece of no length: the next starts here, from its (rolled) frame, as in tracePHelicoids().
            f = lane.h.frameFromTheta(lane.theta);
            ++lane.piece;
        }
        return false;
    };
    std::size_t next = 0;
    const auto feed = [&](int ln) {
        Lane& lane = lanes[ln];
        lane.active = false;
        while (next < count) {
            lane.strand = next++;
            lane.piece = 0;
            lane.at = 1;
            const PHelicoidRequest& r = strands[lane.strand];
            out[lane.strand][0] = Vec3f(r.root);
            if (startPiece(ln, r.root, r.frame)) {
                lane.active = true;
                return;
            }
        }
        // Idle: keep stepping harmless values.
        L.set(ln, Helicoid{}, Vec3d(0.0), Vec3d(1.0, 0.0, 0.0), 0.0, 0.0);
    };
    int activeLanes = 0;
    for (int l = 0; l < kLanes; ++l) {
        feed(l);
        activeLanes += lanes[l].active;
    }
    while (activeLanes > 0) {
        if (rk4) L.stepRk4();
        else L.stepEuler();
        for (int l = 0; l < kLanes; ++l) {
            Lane& lane = lanes[l];
            if (!lane.active) continue;
            const PHelicoidRequest& r = strands[lane.strand];
            const Vec3d p = L.point(l);
            out[lane.strand][lane.at++] = Vec3f(float(p.x()), float(p.y()), float(p.z()));
            if (--lane.stepsLeft > 0) {
                // The last step of a piece lands on its length.
                if (lane.stepsLeft == 1) L.hstep[l] = (*r.pieces)[lane.piece].length - double(lane.steps - 1) * r.step;
                continue;
            }
            // The piece ends: the next starts here with the frame of Eq. 2 at this point.
            const FrameD f = lane.h.frameFromTheta(L.th[l]);
            ++lane.piece;
            if (!startPiece(l, p, f)) {
                feed(l);
                if (!lane.active) --activeLanes;
            }
        }
    }
}

void tracePHelicoid(const Vec3d& root, const FrameD& frame, const std::vector<HelicoidPiece>& pieces,
                    double step, HelicoidIntegrator integrator, HelicoidTrace& out,
                    const std::vector<Helicoid>* field)
{
    tracePHelicoids(&root, 1, frame, pieces, step, integrator, &out, field);
}

} // namespace vdbhair
