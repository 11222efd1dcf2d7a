#include "Helicoid.h"

#include <vdbhair/Exceptions.h>

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

double Helicoid::theta(const Vec3d& world, double thetaRef) const
{
    const Vec3d d = world - p0;
    const double y1 = d.dot(q.t), y2 = d.dot(q.n), y3 = d.dot(q.b);
    double th = std::atan2(k.kT * y1 + k.kN * y2, 1.0 + k.kN * y1 - k.kT * y2) + k.kB * y3;
    // Unwrap: the multiple of 2π that brings theta closest to its previous value.
    constexpr double twoPi = 2.0 * M_PI;
    th += twoPi * std::nearbyint((thetaRef - th) / twoPi);
    return th;
}

FrameD Helicoid::frameFromTheta(double th) const
{
    const double phi = k.alpha * th;
    const double ct = std::cos(th), st = std::sin(th), cp = std::cos(phi), sp = std::sin(phi);
    FrameD f;
    f.t = (cp * ct) * q.t + (cp * st) * q.n + sp * q.b;
    f.n = (-st) * q.t + ct * q.n;
    f.b = (-sp * ct) * q.t + (-sp * st) * q.n + cp * q.b;
    return f;
}

Vec3d Helicoid::tangent(const Vec3d& world, double& thetaRef) const
{
    thetaRef = theta(world, thetaRef);
    const double phi = k.alpha * thetaRef;
    const double ct = std::cos(thetaRef), st = std::sin(thetaRef), cp = std::cos(phi), sp = std::sin(phi);
    return (cp * ct) * q.t + (cp * st) * q.n + sp * q.b;
}

std::size_t stepCount(double length, double step)
{
    if (!(length > 0.0)) return 0;
    return std::max<std::size_t>(1, std::size_t(std::ceil(length / step - 1e-9)));
}

void tracePHelicoid(const Vec3d& root, const FrameD& frame, const std::vector<HelicoidPiece>& pieces,
                    double step, HelicoidIntegrator integrator, HelicoidTrace& out,
                    const std::vector<Helicoid>* field)
{
    out.points.clear();
    out.frames.clear();
    out.arc.clear();
    out.pieces.clear();
    out.joints.clear();
    std::size_t total = 1;
    for (const HelicoidPiece& pc : pieces) total += stepCount(pc.length, step);
    out.points.reserve(total);
    out.frames.reserve(total);
    out.arc.reserve(total);

    Vec3d p = root;
    FrameD f = frame;
    double s = 0.0;
    for (std::size_t i = 0; i < pieces.size(); ++i) {
        const HelicoidPiece& pc = pieces[i];
        Helicoid h;
        if (field) {
            h = (*field)[i];
        } else {
            h.k = pc.k;
            h.q = f.rolled(pc.roll);
            h.p0 = p;
        }
        out.pieces.push_back(h);
        out.joints.push_back(i == 0 ? 0 : out.points.size() - 1);
        // theta along this piece, unwrapped from its value at the piece's first point.
        double th = h.theta(p, 0.0);
        FrameD fr = h.frameFromTheta(th);
        if (i == 0) {
            out.points.push_back(p);
            out.frames.push_back(fr);
            out.arc.push_back(0.0);
        } else {
            out.frames.back() = fr;  // the joint takes the new piece's frame
        }
        const std::size_t n = stepCount(pc.length, step);
        for (std::size_t j = 0; j < n; ++j) {
            const double hstep = (j + 1 == n) ? pc.length - double(n - 1) * step : step;
            if (integrator == HelicoidIntegrator::Euler) {
                p += hstep * fr.t;  // Eq. 3: p_{i+1} = p_i + h E_T(p_i)
            } else {
                double t2 = th, t3 = th, t4 = th;
                const Vec3d k1 = fr.t;
                const Vec3d k2 = h.tangent(p + 0.5 * hstep * k1, t2);
                const Vec3d k3 = h.tangent(p + 0.5 * hstep * k2, t3);
                const Vec3d k4 = h.tangent(p + hstep * k3, t4);
                p += (hstep / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
            }
            th = h.theta(p, th);
            fr = h.frameFromTheta(th);
            s += hstep;
            out.points.push_back(p);
            out.frames.push_back(fr);
            out.arc.push_back(s);
        }
        f = out.frames.back();
    }
}

} // namespace vdbhair
