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
        Vec3d p = trace.points[i] + (w.amplitude * ca) * f.b + (w.amplitude * sa) * f.n;
        if (w.noise > 0.0) {
            double gn, gb;
            rng.normalPair(gn, gb);
            p += (w.noise * gn) * f.n + (w.noise * gb) * f.b;
        }
        out[i] = Vec3f(float(p.x()), float(p.y()), float(p.z()));
    }
}

} // namespace vdbhair
