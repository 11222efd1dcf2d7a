/// @file SplitSearch.h
/// @brief Where a fragment of the strand is split (Piuze et al. 2011, §5.3): the upper limit of
/// the split, the longest prefix whose fit is acceptable, found by a SplitSearch strategy
/// (HelicoidFit.h); then backtracking along the curvature profile. Internal to the fitter;
/// docs/fitting.md gives the measurements behind each number.
#pragma once

#include <vdbhair/helicoid/HelicoidFit.h>
#include <vdbhair/helicoid/impl/FitStarts.h>
#include <vdbhair/helicoid/impl/PieceFit.h>

#include <cstddef>
#include <vector>

namespace vdbhair {
namespace fit {

/// A candidate's pre-fit stops once every vertex is within this fraction of the tolerance of its
/// arc-length counterpart: it only has to be judged (wavy: 768 -> 645 evaluations per strand).
constexpr double kPrefitStopFraction = 0.7;
/// A pre-fit of a whole fragment within this many tolerances is polished before it is judged.
constexpr double kPolishMargin = 1.25;
/// Starts pre-fitted for the last piece allowed (kept whatever its error).
constexpr int kLastPieceStarts = 4;
/// The forward search's first candidate for the first piece: where the strand has turned this
/// much (radians; 1 rad measured: the same mean, a worse p95).
constexpr double kSearchTurn = 2.0;
/// The forward search's gallop: an acceptable candidate is followed by one this many times as
/// long (2 measured: 4 % more evaluations, the same errors).
constexpr double kSearchGrowth = 1.5;
/// The top-down search's first candidate: this fraction of the fragment (the paper's threshold).
constexpr double kSplitFraction = 0.6;
/// Both searches stop within this fraction of the fragment's vertices (one vertex measured: the
/// same error, more evaluations).
constexpr double kSplitResolution = 0.1;
/// The split backtracks from the upper limit within this fraction of the piece.
constexpr double kBacktrackWindow = 0.4;
/// No backtracking for a fit that ends within this fraction of the tolerance of its target
/// vertex ...
constexpr double kKeepOffset = 0.7;
/// ... and within this angle (radians) of the strand's direction there (0.5 and 0.1 rad, the
/// former values, cut the short pieces of wavy hair back nearly always).
constexpr double kKeepAngle = 0.3;

/// @brief How a candidate fit of a fragment runs (FragmentCandidates::fit()).
struct CandidateOptions
{
    PieceStarts which = PieceStarts::All;
    const std::vector<double>* hint = nullptr;  ///< a fit of [a, hintEnd], the nearest found
    std::size_t hintEnd = 0;
    int startsToRun = 0;                        ///< 0: kPrefitStarts
};

/// @brief The fragments [start.a, b] of one piece's search within one tolerance: candidate fits
/// and their acceptance (PieceFitter::acceptable()).
class FragmentCandidates
{
public:
    FragmentCandidates(PieceFitter& fitter, const PieceStart& start, double tolerance)
        : mFitter(fitter), mStart(start), mTolerance(tolerance) {}

    PieceFitter& fitter() const { return mFitter; }
    const PieceStart& start() const { return mStart; }
    double tolerance() const { return mTolerance; }

    /// @brief A candidate fit @a x of [a, @a b] (pre-fitted, not polished; its pre-fit stops at
    /// kPrefitStopFraction of the tolerance, and at the first start that is acceptable).
    /// @return whether it is acceptable within the tolerance
    bool fit(std::size_t b, std::vector<double>& x, const CandidateOptions& options = {});

    /// @brief Whether @a x of [a, @a b] is acceptable within @a eps (world units).
    bool acceptable(std::size_t b, const std::vector<double>& x, double eps) { return mFitter.acceptable(mStart, b, x, eps); }

    /// @brief Polish @a x of [a, @a b] on Eq. 5 (@a ok: it is acceptable now); a polish that makes
    /// an acceptable fit unacceptable is undone (Eq. 5 weighs the mean leash, acceptance the maximum).
    /// @return whether the fit kept is acceptable
    bool polish(std::size_t b, std::vector<double>& x, bool ok);

private:
    PieceFitter& mFitter;
    const PieceStart& mStart;
    double mTolerance;
};

struct SplitOptions
{
    SplitSearch strategy = SplitSearch::Forward;  ///< TopDown is used without a pre-fit whatever this says
    bool lastPiece = false;      ///< the last piece the budget allows: it takes the whole remainder
    double minLength = 0.0;      ///< the shortest fragment (world units)
    double previousTurn = 0.0;   ///< the turning the previous piece's upper limit covered (0: none yet)
};

/// @brief The piece chosen for the fragment [a, last].
struct PieceChoice
{
    std::size_t end = 0;           ///< the vertex it ends at
    std::vector<double> x;         ///< its scaled parameters (by its own length)
    double upperTurn = 0.0;        ///< the turning its upper limit covered (SplitOptions::previousTurn of the next piece)
};

/// @brief Fit the whole remainder [a, last] (the paper's first fit of a fragment, and the last
/// piece allowed with kLastPieceStarts); a pre-fit that is acceptable, near it (kPolishMargin) or
/// the last piece is polished.
/// @return whether @a x is acceptable
bool fitRemainder(FragmentCandidates& candidates, bool lastPiece, std::vector<double>& x);

/// @brief The upper limit of the split by the forward search (SplitSearch::Forward), polished.
/// @param[out] x its fit
/// @return the limit's vertex (the last vertex: no split)
std::size_t searchForward(FragmentCandidates& candidates, const SplitOptions& options, std::vector<double>& x);

/// @brief The upper limit of the split by the paper's search (SplitSearch::TopDown), after the
/// whole remainder's fit @a whole failed; polished with a pre-fit.
/// @param[out] x its fit
/// @return the limit's vertex
std::size_t searchTopDown(FragmentCandidates& candidates, const SplitOptions& options, const std::vector<double>& whole,
                          std::vector<double>& x);

/// @brief Backtrack from the upper limit @a u with fit @a xu along the curvature profile (the
/// paper's rule) to the vertex where fragment and fit differ least in curvature and direction,
/// within the last kBacktrackWindow of the piece and leaving at least @a minLength; a fit ending
/// within kKeepOffset of the tolerance and kKeepAngle of the strand's direction keeps u.
/// @return the vertex the piece ends at
std::size_t backtrackSplit(FragmentCandidates& candidates, std::size_t u, const std::vector<double>& xu, double minLength);

/// @brief The piece for the fragment [a, last]: the whole remainder if acceptable (or the last
/// piece allowed), else the split found by options.strategy and backtracked.
PieceChoice choosePiece(FragmentCandidates& candidates, const SplitOptions& options);

} // namespace fit
} // namespace vdbhair
