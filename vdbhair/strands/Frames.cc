#include "Frames.h"

#include <vdbhair/strands/Measures.h>

#include <cmath>
#include <vector>

namespace vdbhair {

namespace {

Vec3f normalizedOr(const Vec3f& v, const Vec3f& fallback)
{
    const float len = v.length();
    return len > 1e-20f ? v / len : fallback;
}

/// The unit of @a v's component perpendicular to unit @a t, or perpendicularTo(t).
Vec3f orthogonalize(const Vec3f& v, const Vec3f& t)
{
    const Vec3f w = v - t * v.dot(t);
    const float len = w.length();
    return len > 1e-6f ? w / len : perpendicularTo(t);
}

} // namespace

Vec3f perpendicularTo(const Vec3f& t)
{
    // The world axis least aligned with t (ties go to x, then y): never parallel to t.
    int k = 0;
    if (std::abs(t.y()) < std::abs(t[k])) k = 1;
    if (std::abs(t.z()) < std::abs(t[k])) k = 2;
    Vec3f axis(0.f);
    axis[k] = 1.f;
    return normalizedOr(t.cross(axis), Vec3f(0.f, 1.f, 0.f));
}

void frenetFrames(const Vec3f* points, std::size_t n, Frame* out)
{
    if (n == 0) return;
    std::vector<Vec3f> tangents(n);
    computeTangents(points, n, tangents.data());
    for (std::size_t i = 0; i < n; ++i) {
        if (tangents[i].lengthSqr() == 0.f) tangents[i] = Vec3f(1.f, 0.f, 0.f);
    }
    // Normals where the curvature defines them (interior vertices that bend).
    std::vector<Vec3f> normal(n, Vec3f(0.f));
    std::ptrdiff_t firstDefined = -1;
    for (std::size_t i = 1; i + 1 < n; ++i) {
        const Vec3f a = points[i] - points[i - 1];
        const Vec3f b = points[i + 1] - points[i];
        const Vec3f c = a.cross(b);
        const float la = a.length(), lb = b.length(), lc = c.length();
        if (la == 0.f || lb == 0.f || lc <= 1e-6f * la * lb) continue;
        normal[i] = orthogonalize(c.cross(tangents[i]) / lc, tangents[i]);  // n = b x t
        if (firstDefined < 0) firstDefined = std::ptrdiff_t(i);
    }
    Vec3f carried = firstDefined >= 0 ? normal[std::size_t(firstDefined)]
                                      : perpendicularTo(tangents[0]);
    for (std::size_t i = 0; i < n; ++i) {
        Vec3f nrm = normal[i];
        const bool endpoint = (i == 0 || i + 1 == n);
        if (endpoint && n > 2) nrm = normal[i == 0 ? 1 : n - 2];
        if (nrm.lengthSqr() == 0.f) nrm = carried;
        Frame& f = out[i];
        f.t = tangents[i];
        f.n = orthogonalize(nrm, f.t);
        f.b = f.t.cross(f.n);
        carried = f.n;
    }
}

void parallelTransportFrames(const Vec3f* points, std::size_t n, const Vec3f& initialNormal,
                             Frame* out)
{
    if (n == 0) return;
    std::vector<Vec3f> t(n);
    computeTangents(points, n, t.data());
    for (std::size_t i = 0; i < n; ++i) {
        if (t[i].lengthSqr() == 0.f) t[i] = (i > 0) ? t[i - 1] : Vec3f(1.f, 0.f, 0.f);
    }
    Vec3d r(0.0);
    {
        const Vec3f r0 = orthogonalize(initialNormal, t[0]);
        r = Vec3d(r0.x(), r0.y(), r0.z());
    }
    auto toD = [](const Vec3f& v) { return Vec3d(v.x(), v.y(), v.z()); };
    for (std::size_t i = 0; i < n; ++i) {
        if (i > 0) {
            // Double reflection: reflect in the bisector plane of the chord, then in the plane
            // that maps the reflected tangent onto the next tangent.
            const Vec3d v1 = toD(points[i]) - toD(points[i - 1]);
            const double c1 = v1.dot(v1);
            Vec3d rL = r, tL = toD(t[i - 1]);
            if (c1 > 0.0) {
                rL = r - (2.0 / c1) * v1.dot(r) * v1;
                tL = tL - (2.0 / c1) * v1.dot(tL) * v1;
            }
            const Vec3d v2 = toD(t[i]) - tL;
            const double c2 = v2.dot(v2);
            r = (c2 > 0.0) ? rL - (2.0 / c2) * v2.dot(rL) * v2 : rL;
        }
        Frame& f = out[i];
        f.t = t[i];
        f.n = orthogonalize(Vec3f(float(r.x()), float(r.y()), float(r.z())), f.t);
        f.b = f.t.cross(f.n);
        r = Vec3d(f.n.x(), f.n.y(), f.n.z());  // keep it exactly orthonormal
    }
}

void parallelTransportFrames(const Vec3f* points, std::size_t n, Frame* out)
{
    if (n == 0) return;
    std::vector<Frame> frenet(n);
    frenetFrames(points, n, frenet.data());
    parallelTransportFrames(points, n, frenet[0].n, out);
}

} // namespace vdbhair
