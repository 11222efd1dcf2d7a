/// @file HelicoidFit.h
/// @brief Fitting p-helicoids to unparameterized strands (Piuze et al. 2011, §5.2-5.3).
///
/// Tracing: fits are stored for `vdbhair grow` as scenes that trace with RK4 (scene key
/// "integrator"): a fit is a streamline, and forward Euler (Eq. 3) would drift from it by half a
/// step per radian turned. Grow traces at the scene's step, a quarter of the mean segment length
/// by default; the objective traces the same streamlines at four times that step (about one point
/// per target vertex), a quarter of the cost; pieces are chained — and the reported errors
/// measured — with the trace grow will produce. No objective step may turn more than a radian
/// (bounds on k). Discrete Fréchet measures compare vertices, so the target is densified to the
/// trace's spacing first (otherwise a perfect fit of a sparse strand would report half a segment).
///
/// One piece (Eq. 5): k minimizes C(h, H(k, Q, p0, L)) + λ|k| by Nelder–Mead (NLopt's), with Q
/// the strand's discrete Frenet frame at the root (perpendicularTo(T) for the normal where the
/// root is straight, Frames.h), p0 the root and L the fragment's length. vdbhair makes the terms
/// scale-free so one λ serves every hairstyle: C is the Fréchet coupling's mean leash divided by
/// L, and |k| = ‖(kT, kN, kB)‖·L/2π + |alpha| (turns per piece); λ = 1e-3 by default, enough to
/// pick the gentlest of equally good fits without biasing real ones (measured in the benchmark).
///
/// Deviation for speed (`prefitIterations` > 0, the default): Nelder–Mead from raw starts spent
/// ~300 evaluations of Eq. 5 per candidate piece (2,600 per straight strand, ~120 strands/s on
/// 2 cores). Instead each start is first pre-fitted by Levenberg–Marquardt on a smooth stand-in:
/// both curves are parameterized by arc length, so the residuals are trace(s_i) - h_i at the
/// target's own vertices (plus the end point again, the end direction against the strand's —
/// the next piece starts with this one's end frame, C¹ — weighted by `endTangentWeight`, and a
/// small Tikhonov term), an O(n) least-squares problem (the end direction, measured at 0.3:
/// straight 1.66 % -> 1.49 %, curly 2.00 % -> 1.74 %, with fewer pieces); the Jacobian is by forward differences once, then Broyden updates (one trace
/// per iteration). Its traces take one RK4 step per segment, or one step over up to four segments
/// where the strand turns less than `prefitMaxTurn`, with Hermite-interpolated vertices (23 % less
/// CPU on straight hair; such steps can stray from the streamline where the field turns fast off
/// the curve, so acceptance is always judged on the trace grow produces). The piece kept is then polished by a short Nelder–Mead on Eq. 5 itself (`polishEvaluations`, from
/// a small simplex), so the result is still the paper's objective, locally; a polish that would
/// push an acceptable piece over `maxError` is undone (Eq. 5 weighs the mean leash, acceptance
/// the maximum). `prefitIterations` = 0 restores Nelder–Mead alone.
/// Starts: the strand's curvature and torsion near the fragment's start — kT = mean curvature,
/// alpha = mean torsion / curvature, the frame rolled so its normal is the strand's Frenet normal
/// there — and, for whole fragments, k = 0 and the previous piece's k; the `prefitStarts` with
/// the lowest pre-fit cost are pre-fitted in that order, stopping at the first within `maxError`
/// (the last piece allowed tries `lastPieceStarts`). A candidate of the split search starts from the nearest fit already found.
///
/// Pieces (§5.3): a fragment whose fit's discrete Fréchet distance is within `maxError` of the
/// strand's length is accepted; otherwise the fragment is split. The upper limit of the split is
/// the longest prefix whose fit is acceptable (the paper's Fréchet threshold), searched by
/// bisection from the `splitFraction` of the fragment (60 %, the paper's value) upwards if that is
/// acceptable, towards the minimum fragment if not, to within `splitResolution` of its vertices;
/// candidates are judged by their pre-fits with discreteFrechetWithin (the decision version, which
/// stops early), and only the chosen one is polished. From that limit the split backtracks along
/// the curvature profile to the vertex where fragment and fit differ least in curvature (and
/// direction), within the last 40 % of the piece, never leaving a fragment shorter than
/// `minFragment` of the strand. Each piece starts at the end of the previous fitted piece with
/// its frame (C¹, as the paper's pieces), so only k — and, with `optimizeRoll`, a roll about the
/// tangent — is fitted after the first. The first piece fits a roll too: the strand's Frenet
/// normal at the root is rarely the normal of the helicoid that generated it (measured before the
/// pre-fit: 1.84 % -> 1.57 % mean error on straight.hair).
///
/// Measured (vdbhair_benchmark --sections fit --fit-strands 500 --reps 1, 2 threads, strands
/// resampled to 30 vertices; mean / p95 discrete Fréchet error relative to length, pieces,
/// evaluations per strand, strands/s; wall-clock rates vary ±40 % with other load on the machine):
///   straight 1.52 % / 1.97 %, 2.26 pieces, 234, 1489/s   (before the pre-fit: 1.58 %, 2.16, 2645, 118/s)
///   wavy     2.99 % / 5.46 %, 7.82 pieces, 1076, 490/s   (before: 3.84 %, 7.93, 10260, 51/s)
///   curly    1.74 % / 2.00 %, 4.06 pieces, 516, 848/s    (before: 1.95 %, 4.36, 5886, 72/s)
///   short    1.50 % / 1.96 %, 2.28 pieces, 226, 1575/s   (before: 1.71 %, 2.13, 2389, 118/s)
/// Wavy (harolongo: noisy coils, about 33° of turning per segment and ~600° per strand) stays
/// short of 2 %. Our reading: with phi = alpha·theta a helicoid cannot hold a helix's constant
/// tilt, so a piece follows a coil for less than a turn, and C¹ joints pass each piece's
/// direction error on to the next. More pieces help little (maxPieces 12 or 16: 2.53 %, 8.3
/// pieces: the split search then ends at the 8 % minimum fragment, whose fit can still fail),
/// nor did pre-fitting every start for split candidates (3.0-3.2 %, measured before the end
/// direction residual).
/// Kept fits have kT >= 0: a negative kT is flipped with a half-turn roll of the frame, the same
/// curve (§3's sign symmetry; with Eq. 1 as printed it is a half turn about E_T).
#pragma once

#include <vdbhair/helicoid/Helicoid.h>
#include <vdbhair/strands/StrandSet.h>

#include <openvdb/util/NullInterrupter.h>

#include <cstddef>
#include <string>
#include <vector>

namespace vdbhair {

struct FitParams
{
    double maxError = 0.02;       ///< accepted discrete Fréchet distance, as a fraction of the strand length
    double lambda = 1e-3;         ///< regularization weight (dimensionless, see above)
    int maxPieces = 16;           ///< most pieces per strand (see capByPoints)
    bool capByPoints = true;      ///< also at most (3 n - 10) / 6 pieces for n vertices: a fit never has more floats than its points
    bool forwardSearch = true;    ///< search the split's upper limit forwards from a guess (else top-down from splitFraction, the paper's reading)
    double searchTurn = 2.0;      ///< the forward search's first candidate for the first piece: where the strand has turned this much (radians)
    double searchGrowth = 2.0;    ///< the forward search's gallop: an acceptable candidate is followed by one this many times as long
    double splitFraction = 0.6;   ///< the paper's Fréchet threshold for the split's upper limit (top-down search)
    double minFragment = 0.03;    ///< shortest piece, as a fraction of the strand length (and at least two segments)
    double splitResolution = 0.1; ///< the search for the upper limit stops within this fraction of the fragment's vertices (0: one vertex)
    double acceptEndOffset = 0.7; ///< a piece before the last is accepted only if it also ends within this fraction of the tolerance of its target vertex (the next piece starts there)
    double backtrackWindow = 0.4; ///< the split backtracks from the upper limit within this fraction of the piece
    double keepOffset = 0.7;      ///< no backtracking for a fit ending within this fraction of the tolerance of its target vertex ...
    double keepAngle = 0.3;       ///< ... and within this angle (radians) of the strand's direction there
    int relaxRetries = 2;         ///< refits of a strand that used every piece allowed and still misses maxError, each with relaxFactor times the tolerance
    double relaxFactor = 1.4;
    bool optimizeRoll = true;     ///< also fit a roll angle for pieces after the first (measured: halves the mean error)
    int maxEvaluations = 300;     ///< Nelder–Mead evaluations per piece without a pre-fit
    int polishEvaluations = 20;   ///< Nelder–Mead evaluations of a polish after the pre-fit (0: no polish)
    int prefitIterations = 10;    ///< Levenberg–Marquardt iterations of the pre-fit per start (0: none, Nelder–Mead from the raw starts)
    double prefitStopFraction = 0.7; ///< a search candidate's pre-fit stops once every vertex is within this fraction of the tolerance of its arc-length counterpart (0: never)
    double endTangentWeight = 0.45; ///< pre-fit weight of the end direction's residual (unit vectors; positions count as fractions of L)
    double prefitMaxTurn = 0.3;   ///< radians an RK4 step of the pre-fit may turn when it spans several segments (0: one step per segment)
    bool broyden = true;          ///< pre-fit Jacobians by Broyden updates (else forward differences every iteration)
    int prefitStarts = 2;         ///< starts pre-fitted for a whole fragment, the best by the pre-fit's cost at the start (3: all; measured on wavy: 2.99 % with 2, 3.05 % with 3 at 11 % more evaluations, 3.95 % with 1)
    bool firstGoodStart = true;   ///< stop at the first pre-fit within maxError (else pre-fit every start and keep the best)
    int lastPieceStarts = 4;      ///< starts pre-fitted for the last piece allowed (kept whatever its error)
    double prefitGain = 1e-2;     ///< the pre-fit stops when an iteration lowers its cost by less than this fraction
    double polishMargin = 1.25;   ///< a pre-fit of a whole fragment within this many maxError is polished before it is judged
    double polishStep = 0.05;     ///< Nelder–Mead's initial step after a pre-fit (scaled parameters; 0.5 without)
    double polishTolerance = 1e-3; ///< Nelder–Mead's absolute tolerance on the scaled parameters
    double step = 0.0;            ///< the regrown strands' tracing step (world units); 0: a quarter of the mean segment length
};

struct StrandFit
{
    Vec3d root{0.0};
    FrameD frame;                       ///< Q of the first piece
    std::vector<HelicoidPiece> pieces;
    double step = 0.0;                  ///< the step the pieces were fitted (and must be grown) with
    double frechet = 0.0;               ///< discrete Fréchet distance of the whole fit (world units)
    double coupling = 0.0;              ///< its Fréchet coupling's mean leash (world units)
    double length = 0.0;                ///< the target strand's length
    std::size_t evaluations = 0;        ///< objective evaluations spent
};

/// @brief Fit one strand of @a n points.
/// @throw ValueError for fewer than 2 distinct points or a zero length.
StrandFit fitStrand(const Vec3f* points, std::size_t n, const FitParams& params);

/// @brief Fit every strand (in parallel, independent of the thread count); each at its own scale
/// (its own step) unless params.step is given.
/// @param[out] errors optional: #S messages, empty where the strand was fitted; without it the
/// first failure throws.
/// @param interrupter optional progress and Ctrl-C (Progress.h).
/// @throw InterruptedError when the interrupter stops the work.
std::vector<StrandFit> fitStrands(const StrandSet& strands, const FitParams& params, bool threaded = true,
                                  std::vector<std::string>* errors = nullptr,
                                  openvdb::util::NullInterrupter* interrupter = nullptr);

/// @brief The trace of a fit (as grown from a scene with the fit's step).
void traceFit(const StrandFit& fit, HelicoidTrace& out);

/// @brief What `vdbhair fit` and the benchmark report about a set of fits.
struct FitSummary
{
    std::size_t strands = 0, fitted = 0, skipped = 0;
    std::size_t overMaxError = 0;   ///< fits whose discrete Fréchet distance exceeds maxError · length
    double meanRelative = 0.0;      ///< mean discrete Fréchet distance relative to strand length
    double p95Relative = 0.0;       ///< its 95th percentile
    double piecesPerStrand = 0.0;
    double fitBytes = 0.0;          ///< floats: root, frame (t, n) per strand; k, length, roll per piece
    double pointBytes = 0.0;        ///< 3 floats per input vertex
    double evaluationsPerStrand = 0.0;
};

/// @brief Summarize @a fits of @a strands (@a errors as from fitStrands: non-empty where a strand
/// was not fitted, and left out).
FitSummary summarizeFits(const StrandSet& strands, const std::vector<StrandFit>& fits,
                         const std::vector<std::string>& errors, double maxError);

} // namespace vdbhair
