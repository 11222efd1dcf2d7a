#include "PrefitTrace.h"

#include <vdbhair/helicoid/FastMath.h>

#include <algorithm>
#include <cmath>

namespace vdbhair {
namespace fit {

namespace {

/// Helicoid::tangent() with the branchless forms of fastmath's functions (the same polynomials):
/// the pre-fit's traces call it millions of times, and the branches of the scalar forms (the
/// quadrant of sin/cos, the reduction of atan) follow the data.
inline Vec3d prefitTangent(const Helicoid& h, const Vec3d& world, double& thetaRef)
{
    const Vec3d d = world - h.p0;
    const double y1 = d.dot(h.q.t), y2 = d.dot(h.q.n), y3 = d.dot(h.q.b);
    double th = fastmath::atan2Lane(h.k.kT * y1 + h.k.kN * y2, 1.0 + h.k.kN * y1 - h.k.kT * y2) + h.k.kB * y3;
    constexpr double twoPi = 2.0 * M_PI;
    th += twoPi * fastmath::roundLane((thetaRef - th) * (1.0 / twoPi));
    thetaRef = th;
    double ct, st, cp, sp;
    fastmath::sinCosLane(th, st, ct);
    fastmath::sinCosLane(h.k.alpha * th, sp, cp);
    return (cp * ct) * h.q.t + (cp * st) * h.q.n + sp * h.q.b;
}

} // namespace

void traceAtVertices(const Helicoid& h, const FitTarget& target, std::size_t a, std::size_t b, double maxStep,
                     std::vector<Vec3d>& out, Vec3d* endTangent)
{
    out.resize(b - a + 1);
    Vec3d p = h.p0;
    double th = h.theta(p, 0.0);
    Vec3d k1 = h.frameFromTheta(th).t;
    out[0] = p;
    // Kutta's third-order rule: one tangent fewer per step than RK4 (the last one is the next
    // step's first).
    auto advance = [&](double hs) {
        double t2 = th, t3 = th;
        const Vec3d k2 = prefitTangent(h, p + 0.5 * hs * k1, t2);
        const Vec3d k3 = prefitTangent(h, p + hs * (2.0 * k2 - k1), t3);
        p += (hs / 6.0) * (k1 + 4.0 * k2 + k3);
        k1 = prefitTangent(h, p, th);
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
