#include "Wisp.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace vdbhair {

namespace {

/// Rotate @a v about unit @a axis by the angle whose cosine and sine are @a c, @a s (Rodrigues).
Vec3d rotate(const Vec3d& v, const Vec3d& axis, double c, double s)
{
    return v * c + axis.cross(v) * s + axis * (axis.dot(v) * (1.0 - c));
}

} // namespace

void traceWisps(const HelicoidTrace& guide, const std::vector<HelicoidPiece>& pieces, const WispParams& params,
                double step, HelicoidIntegrator integrator, Rng* rngs, std::size_t count, HelicoidTrace* outs, bool frames)
{
    // Roots: uniform in the disk (r = R sqrt(u)) in the guide root's E_N–E_B plane.
    const FrameD& f0 = guide.pieces.front().q;
    std::vector<Vec3d> roots(count);
    for (std::size_t i = 0; i < count; ++i) {
        const double r = params.radius * std::sqrt(rngs[i].uniform()), a = 2.0 * M_PI * rngs[i].uniform();
        roots[i] = guide.points.front() + (r * std::cos(a)) * f0.n + (r * std::sin(a)) * f0.b;
    }
    tracePHelicoids(roots.data(), count, f0, pieces, step, integrator, outs, &guide.pieces);

    // Fanning: a rigid rotation about each wisp strand's root.
    for (std::size_t w = 0; w < count; ++w) {
        Rng& rng = rngs[w];
        HelicoidTrace& out = outs[w];
        const double z = 2.0 * rng.uniform() - 1.0, az = 2.0 * M_PI * rng.uniform();
        const double angle = params.fanning * rng.uniform();
        if (!(params.fanning > 0.0) || angle == 0.0) continue;
        const double rz = std::sqrt(std::max(0.0, 1.0 - z * z));
        const Vec3d axis(rz * std::cos(az), rz * std::sin(az), z);
        const double c = std::cos(angle), s = std::sin(angle);
        const Vec3d root = roots[w];
        for (std::size_t i = 0; i < out.points.size(); ++i) {
            out.points[i] = root + rotate(out.points[i] - root, axis, c, s);
            if (!frames) continue;
            FrameD& fr = out.frames[i];
            fr.t = rotate(fr.t, axis, c, s);
            fr.n = rotate(fr.n, axis, c, s);
            fr.b = rotate(fr.b, axis, c, s);
        }
    }
}

void traceWisp(const HelicoidTrace& guide, const std::vector<HelicoidPiece>& pieces, const WispParams& params,
               double step, HelicoidIntegrator integrator, Rng& rng, HelicoidTrace& out)
{
    traceWisps(guide, pieces, params, step, integrator, &rng, 1, &out);
}

} // namespace vdbhair
