#include "Wisp.h"

#include <vdbhair/Rotation.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace vdbhair {

namespace {

/// Rotate @a out rigidly about @a root (points, and frames when asked).
void rotateTrace(HelicoidTrace& out, const Vec3d& root, const Vec3d& axis, double angle, bool frames)
{
    const double c = std::cos(angle), s = std::sin(angle);
    for (std::size_t i = 0; i < out.points.size(); ++i) {
        out.points[i] = root + rotateAbout(out.points[i] - root, axis, c, s);
        if (!frames) continue;
        FrameD& fr = out.frames[i];
        fr.t = rotateAbout(fr.t, axis, c, s);
        fr.n = rotateAbout(fr.n, axis, c, s);
        fr.b = rotateAbout(fr.b, axis, c, s);
    }
}

} // namespace

void traceWisps(const HelicoidTrace& guide, const std::vector<HelicoidPiece>& pieces, const WispParams& params,
                double step, HelicoidIntegrator integrator, Rng* rngs, std::size_t count, HelicoidTrace* outs, bool frames)
{
    // Roots: uniform in the disk (r = R sqrt(u)), in the guide root's E_N–E_B plane or, with a
    // normal, in the plane perpendicular to it (axes: the guide's tangent projected into that
    // plane, or its E_N when the tangent is along the normal, and their cross product).
    const FrameD& f0 = guide.pieces.front().q;
    Vec3d du = f0.n, dv = f0.b;
    const double normalLength = params.normal.length();
    const bool hasNormal = normalLength > 0.0;
    Vec3d normal(0.0);
    if (hasNormal) {
        normal = params.normal / normalLength;
        du = f0.t - normal * normal.dot(f0.t);
        if (du.length() < 1e-6) du = f0.n - normal * normal.dot(f0.n);
        du.normalize();
        dv = normal.cross(du);
    }
    std::vector<Vec3d> roots(count);
    for (std::size_t i = 0; i < count; ++i) {
        const double r = params.radius * std::sqrt(rngs[i].uniform()), a = 2.0 * M_PI * rngs[i].uniform();
        roots[i] = guide.points.front() + (r * std::cos(a)) * du + (r * std::sin(a)) * dv;
    }
    tracePHelicoids(roots.data(), count, f0, pieces, step, integrator, outs, &guide.pieces);

    for (std::size_t w = 0; w < count; ++w) {
        Rng& rng = rngs[w];
        HelicoidTrace& out = outs[w];
        // Fanning: a rigid rotation about each wisp strand's root.
        const double z = 2.0 * rng.uniform() - 1.0, az = 2.0 * M_PI * rng.uniform();
        const double angle = params.fanning * rng.uniform();
        if (params.fanning > 0.0 && angle != 0.0) {
            const double rz = std::sqrt(std::max(0.0, 1.0 - z * z));
            rotateTrace(out, roots[w], Vec3d(rz * std::cos(az), rz * std::sin(az), z), angle, frames);
        }
        // Strays: a larger rotation for a fraction of the strands (three draws, only when asked).
        if (params.strays > 0.0) {
            const double pick = rng.uniform(), size = rng.uniform(), around = 2.0 * M_PI * rng.uniform();
            if (pick < params.strays) {
                const double sense = size < 0.5 ? -1.0 : 1.0;  // the lower half picks the sense...
                const double strayAngle = params.strayAngle * (0.5 + 0.5 * std::abs(2.0 * size - 1.0));  // ...the rest the size
                const Vec3d axis = hasNormal ? normal : std::cos(around) * f0.n + std::sin(around) * f0.b;
                // With a normal, about the line through the guide's root (for a sphere head, through
                // its centre): the stray's root turns within the disk, and nothing enters the head.
                const Vec3d& pivot = hasNormal ? guide.points.front() : roots[w];
                if (strayAngle != 0.0) rotateTrace(out, pivot, axis, sense * strayAngle, frames);
            }
        }
    }
}

void traceWisp(const HelicoidTrace& guide, const std::vector<HelicoidPiece>& pieces, const WispParams& params,
               double step, HelicoidIntegrator integrator, Rng& rng, HelicoidTrace& out)
{
    traceWisps(guide, pieces, params, step, integrator, &rng, 1, &out);
}

} // namespace vdbhair
