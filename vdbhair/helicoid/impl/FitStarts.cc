#include "FitStarts.h"

#include <vdbhair/strands/Measures.h>

#include <algorithm>
#include <cmath>

namespace vdbhair {
namespace fit {

void estimateCurvatureTorsion(const FitTarget& target, std::size_t a, std::size_t b, double& kappa, double& tau)
{
    const std::size_t n = b - a + 1;
    std::vector<Vec3f> pts(n);
    for (std::size_t i = 0; i < n; ++i) pts[i] = toFloat(target.pts[a + i]);
    std::vector<float> k(n), t(n);
    curvatureProfile(pts.data(), n, k.data());
    torsionProfile(pts.data(), n, t.data());
    const std::size_t m = std::max<std::size_t>(1, n / 3);
    kappa = tau = 0.0;
    for (std::size_t i = 0; i < m; ++i) { kappa += k[i]; tau += t[i]; }
    kappa /= double(m);
    tau /= double(m);
}

std::vector<std::vector<double>> pieceStarts(const FitTarget& target, const PieceStart& start, std::size_t b, std::size_t dims,
                                             const StartOptions& options)
{
    const std::size_t a = start.a;
    const double L = target.arc[b] - target.arc[a];
    const bool all = options.which == PieceStarts::All;
    std::vector<std::vector<double>> starts;
    // The strand's curvature and torsion near the start, with the frame rolled so that its
    // normal is the strand's Frenet normal there.
    if (all || !options.hint) {
        double kappa, tau;
        estimateCurvatureTorsion(target, a, b, kappa, tau);
        starts.push_back({kappa * L, 0.0, 0.0, kappa > 1e-9 ? std::max(-2.0, std::min(2.0, tau / kappa)) : 0.0});
        if (dims > 4) {
            const Vec3d& n = target.normal[a];
            starts.back().push_back(std::atan2(n.dot(start.q.b), n.dot(start.q.n)));
        }
    }
    if (options.hint) {
        std::vector<double> h = *options.hint;
        for (int k = 0; k < 3; ++k) h[std::size_t(k)] *= L / options.hintLength;
        starts.push_back(h);
    }
    if (all) {
        starts.push_back({0.0, 0.0, 0.0, 0.0});
        const std::vector<double>& p = start.previous;
        if (!p.empty()) starts.push_back({p[0] * L, p[1] * L, p[2] * L, p[3]});
    }
    return starts;
}

} // namespace fit
} // namespace vdbhair
