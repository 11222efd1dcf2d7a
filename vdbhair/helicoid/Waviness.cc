#include "Waviness.h"

#include <vdbhair/helicoid/FastMath.h>

#include <cmath>

namespace vdbhair {

void applyWaviness(const HelicoidTrace& trace, const WavinessParams& w, Rng& rng, Vec3f* out)
{
    for (std::size_t i = 0; i < trace.points.size(); ++i) {
        const FrameD& f = trace.frames[i];
        const double angle = w.frequency * trace.arc[i] + w.phase;
        double sa, ca;
        fastmath::sinCos(angle, sa, ca);  // agrees with the library to ~1e-15 (tests/helicoid/TestFastMath.cc)
        double scale = 1.0;
        if (w.ramp > 0.0 && trace.arc[i] < w.ramp) {
            const double x = trace.arc[i] / w.ramp;
            scale = x * x * (3.0 - 2.0 * x);
        }
        const double a = w.amplitude * scale;
        Vec3d p = trace.points[i] + (a * ca) * f.b + (a * sa) * f.n;
        if (w.noise > 0.0) {
            double gn, gb;
            rng.normalPair(gn, gb);
            p += (w.noise * scale * gn) * f.n + (w.noise * scale * gb) * f.b;
        }
        out[i] = Vec3f(float(p.x()), float(p.y()), float(p.z()));
    }
}

} // namespace vdbhair
