#include "PrefitTrace.h"

#include <vdbhair/field/Streamline.h>
#include <vdbhair/helicoid/AnalyticHelicoidSampler.h>

#include <algorithm>
#include <cmath>

namespace vdbhair {
namespace fit {

void traceAtVertices(const Helicoid& h, const FitTarget& target, std::size_t a, std::size_t b, double maxStep,
                     std::vector<Vec3d>& out, Vec3d* endTangent)
{
    out.resize(b - a + 1);
    Vec3d p = h.p0;
    // The streamline engine's Kutta step (RK3): one tangent fewer per step than RK4, the last
    // one (the next step's start) shared with the next step.
    BranchlessHelicoidSampler sampler(h, h.theta(p, 0.0));
    StreamlineIntegrator<BranchlessHelicoidSampler> kutta(sampler, Integrator::RK3);
    Vec3d k1 = h.frameFromTheta(sampler.theta()).t;
    out[0] = p;
    auto advance = [&](double hs) {
        Vec3d q;
        kutta.advanceFrom<Integrator::RK3>(p, k1, hs, q);  // never fails: a helicoid is defined everywhere
        p = q;
        k1 = sampler.tangent(p);
    };
    // Where the strand turns slowly, one step spans several segments (the strand turning at most
    // kPrefitMaxTurn over them: the steps depend on the fragment only, so the traced positions
    // stay smooth in the parameters for the Jacobian), and the vertices inside it are cubic
    // Hermite interpolants of the step's ends (positions and unit tangents), O(h^4).
    for (std::size_t i = a; i < b;) {
        std::size_t j = i + 1;
        double len = target.arc[j] - target.arc[i];
        double turn = target.turning[i] + target.turning[j];
        while (j < b && j - i < 4 && (turn += target.turning[j + 1]) <= kPrefitMaxTurn) len = target.arc[++j] - target.arc[i];
        if (j == i + 1) {
            const int n = std::max(1, int(std::ceil(len / maxStep - 0.5)));
            for (int m = 0; m < n; ++m) advance(len / n);
        } else {
            const Vec3d pa = p, ta = k1;
            advance(len);
            for (std::size_t m = i + 1; m < j; ++m) {
                const double u = (target.arc[m] - target.arc[i]) / len, u2 = u * u, u3 = u2 * u;
                out[m - a] = (2 * u3 - 3 * u2 + 1) * pa + ((u3 - 2 * u2 + u) * len) * ta + (-2 * u3 + 3 * u2) * p +
                             ((u3 - u2) * len) * k1;
            }
        }
        out[j - a] = p;
        i = j;
    }
    if (endTangent) *endTangent = k1;
}

} // namespace fit
} // namespace vdbhair
