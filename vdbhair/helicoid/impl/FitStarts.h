/// @file FitStarts.h
/// @brief Where a piece's fit starts (HelicoidFit.h): scaled parameters x = (kT L, kN L, kB L,
/// alpha[, roll]) for a fragment of length L, estimated from the strand, taken from a
/// neighbouring fit, or k = 0 and the previous piece's k. Internal to the fitter.
#pragma once

#include <vdbhair/helicoid/Helicoid.h>
#include <vdbhair/helicoid/impl/FitTarget.h>

#include <cstddef>
#include <vector>

namespace vdbhair {
namespace fit {

/// @brief Where a piece starts: the target's vertex @a a, and the point and frame the previous
/// piece ends with (pieces are C¹, §3.4).
struct PieceStart
{
    std::size_t a = 0;
    Vec3d p0{0.0};
    FrameD q;
    std::vector<double> previous;  ///< the previous piece's unscaled (kT, kN, kB, alpha[, roll]); empty for the first
};

/// @brief Which starts a piece's fit tries.
enum class PieceStarts
{
    /// A candidate of the split search: the neighbouring fit it is given (the hint) alone.
    NearestFit,
    /// A whole fragment: the strand's estimate, the hint if any, k = 0 and the previous piece's k.
    All
};

struct StartOptions
{
    PieceStarts which = PieceStarts::All;
    const std::vector<double>* hint = nullptr;  ///< a fit of the fragment [a, c], scaled by its length ...
    double hintLength = 0.0;                    ///< ... this one (world units)
};

/// @brief Mean curvature @a kappa and torsion @a tau over the first third of the fragment [a, b]
/// (curvatureProfile() and torsionProfile(), Measures.h).
void estimateCurvatureTorsion(const FitTarget& target, std::size_t a, std::size_t b, double& kappa, double& tau);

/// @brief The starts of a fit of [start.a, @a b], in the order they are ranked on ties:
/// - the strand's estimate (with All, or without a hint): kT = kappa, alpha = tau / kappa
///   (within ±2), and for @a dims 5 the roll that turns q's normal onto the strand's Frenet
///   normal at a;
/// - the hint, its curvatures rescaled from its length to this fragment's;
/// - with All: k = 0, and the previous piece's k (when there is one), scaled to this fragment.
/// Starts are not padded to @a dims.
std::vector<std::vector<double>> pieceStarts(const FitTarget& target, const PieceStart& start, std::size_t b, std::size_t dims,
                                             const StartOptions& options);

} // namespace fit
} // namespace vdbhair
