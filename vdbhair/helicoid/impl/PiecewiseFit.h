/// @file PiecewiseFit.h
/// @brief The pieces of one strand within one tolerance (Piuze et al. 2011, §5.3): piece after
/// piece from the root, each chosen by choosePiece() (SplitSearch.h) and chained C¹ from its
/// predecessor's end as it will be grown. Internal to the fitter (HelicoidFit.h).
#pragma once

#include <vdbhair/helicoid/HelicoidFit.h>
#include <vdbhair/helicoid/impl/PieceFit.h>

namespace vdbhair {
namespace fit {

/// Shortest piece, as a fraction of the strand length (and at least two segments): 8 % held wavy
/// hair back (2.45 % mean error against 1.76 %).
constexpr double kMinFragment = 0.03;

/// @brief Which pieces must keep params.axisClearance from their singular axis.
enum class KeptPieces
{
    /// Only accepted pieces are checked (PieceFitter::acceptable()); the last piece allowed and a
    /// fragment without an acceptable candidate are kept as fitted: most are streamlines still.
    AsFitted,
    /// Every piece kept: one too near its axis has its curvatures scaled down by 0.8 (up to 30
    /// times) until its trace keeps the distance (k -> 0 moves the axis away as 1/|k|). The refit
    /// of a fit that is not step-converged.
    ClearOfAxis
};

struct PiecewiseOptions
{
    double tolerance = 0.0;   ///< accepted discrete Fréchet distance (world units)
    int maxPieces = 1;        ///< the strand's piece budget
    double minLength = 0.0;   ///< the shortest fragment (world units)
    KeptPieces kept = KeptPieces::AsFitted;
};

/// @brief Fit the pieces of @a fit (its root and frame set) to the fitter's target, replacing
/// fit.pieces.
void fitPieces(PieceFitter& fitter, const PiecewiseOptions& options, StrandFit& fit);

} // namespace fit
} // namespace vdbhair
