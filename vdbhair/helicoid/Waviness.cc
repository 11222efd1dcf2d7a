#include "Waviness.h"

#include <cmath>

namespace vdbhair {

void applyWaviness(const HelicoidTrace& trace, const WavinessParams& w, Rng& rng, Vec3f* out)
{
    for (std::size_t i = 0; i < trace.points.size(); ++i) {
        const FrameD& f = trace.frames[i];
        const double angle = w.frequency * trace.arc[i] + w.phase;
        Vec3d p = trace.points[i] + (w.amplitude * std::cos(angle)) * f.b + (w.amplitude * std::sin(angle)) * f.n;
        if (w.noise > 0.0) p += (w.noise * rng.normal()) * f.n + (w.noise * rng.normal()) * f.b;
        out[i] = Vec3f(float(p.x()), float(p.y()), float(p.z()));
    }
}

} // namespace vdbhair
