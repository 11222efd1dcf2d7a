#include "Helicoid.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/helicoid/FastMath.h>

#include <cmath>

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

std::size_t stepCount(double length, double step)
{
    if (!(length > 0.0)) return 0;
    return std::max<std::size_t>(1, std::size_t(std::ceil(length / step - 1e-9)));
}

void tracePHelicoids(const Vec3d* roots, std::size_t count, const FrameD& frame, const std::vector<HelicoidPiece>& pieces,
                     double step, HelicoidIntegrator integrator, HelicoidTrace* outs, const std::vector<Helicoid>* field)
{
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
                    if (integrator == HelicoidIntegrator::Euler) {
                        p[l] += hstep * fr[l].t;  // Eq. 3: p_{i+1} = p_i + h E_T(p_i)
                    } else {
                        double t2 = th[l], t3 = th[l], t4 = th[l];
                        const Vec3d k1 = fr[l].t;
                        const Vec3d k2 = h[l].tangent(p[l] + 0.5 * hstep * k1, t2);
                        const Vec3d k3 = h[l].tangent(p[l] + 0.5 * hstep * k2, t3);
                        const Vec3d k4 = h[l].tangent(p[l] + hstep * k3, t4);
                        p[l] += (hstep / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
                    }
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

void tracePHelicoid(const Vec3d& root, const FrameD& frame, const std::vector<HelicoidPiece>& pieces,
                    double step, HelicoidIntegrator integrator, HelicoidTrace& out,
                    const std::vector<Helicoid>* field)
{
    tracePHelicoids(&root, 1, frame, pieces, step, integrator, &out, field);
}

} // namespace vdbhair
