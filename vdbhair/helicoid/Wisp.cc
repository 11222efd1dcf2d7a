#include "Wisp.h"

#include <cmath>

namespace vdbhair {

namespace {

/// Rotate @a v by @a angle about unit @a axis (Rodrigues).
Vec3d rotate(const Vec3d& v, const Vec3d& axis, double angle)
{
    const double c = std::cos(angle), s = std::sin(angle);
    return v * c + axis.cross(v) * s + axis * (axis.dot(v) * (1.0 - c));
}

} // namespace

void traceWisp(const HelicoidTrace& guide, const std::vector<HelicoidPiece>& pieces, const WispParams& params,
               double step, HelicoidIntegrator integrator, Rng& rng, HelicoidTrace& out)
{
    // Root: uniform in the disk (r = R sqrt(u)) in the guide root's E_N–E_B plane.
    const FrameD& f0 = guide.pieces.front().q;
    const double r = params.radius * std::sqrt(rng.uniform()), a = 2.0 * M_PI * rng.uniform();
    const Vec3d root = guide.points.front() + (r * std::cos(a)) * f0.n + (r * std::sin(a)) * f0.b;
    tracePHelicoid(root, f0, pieces, step, integrator, out, &guide.pieces);

    // Fanning: a rigid rotation about the wisp's root.
    const double z = 2.0 * rng.uniform() - 1.0, az = 2.0 * M_PI * rng.uniform();
    const double angle = params.fanning * rng.uniform();
    if (params.fanning > 0.0 && angle != 0.0) {
        const double rz = std::sqrt(std::max(0.0, 1.0 - z * z));
        const Vec3d axis(rz * std::cos(az), rz * std::sin(az), z);
        for (std::size_t i = 0; i < out.points.size(); ++i) {
            out.points[i] = root + rotate(out.points[i] - root, axis, angle);
            FrameD& fr = out.frames[i];
            fr.t = rotate(fr.t, axis, angle);
            fr.n = rotate(fr.n, axis, angle);
            fr.b = rotate(fr.b, axis, angle);
        }
    }
}

} // namespace vdbhair
