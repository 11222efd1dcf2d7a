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
/// straight 1.66 % -> 1.49 %, curly 2.00 % -> 1.74 %, with fewer pieces; raised to 0.45 with the
/// forward search below: wavy 1.88 % -> 1.76 %; 0.6 gave 1.69 % with 4 % more pieces). The
/// Jacobian is by forward differences once, then Broyden updates (one trace per iteration); the
/// damped normal equations (at most 5 unknowns) are formed by hand and solved by LDLᵀ with
/// pivoting on the stack (a Cholesky solve that gives up on nearly dependent columns was worse:
/// wavy at the former defaults 3.30 % instead of 3.01 %). Its traces take one step per segment,
/// or one step over up to four segments where the strand turns less than `prefitMaxTurn`, with
/// Hermite-interpolated vertices (23 % less CPU on straight hair; such steps can stray from the
/// streamline where the field turns fast off the curve, so acceptance is always judged on the
/// trace grow produces). A step is Kutta's third-order rule (`prefitOrder` 3: three tangents, the
/// last shared with the next step, against RK4's four; 7 % fewer instructions, and on wavy 1.76 %
/// against RK4's 1.78 %; the midpoint rule saved 14 % but its bias flipped borderline
/// candidates: 1.84 % and twice the strands over maxError), with the branchless forms of
/// fastmath's sin/cos and atan2 (the same polynomials; the scalar forms' branches follow the data:
/// 9 % faster on wavy, interleaved runs on one thread). A search candidate's pre-fit stops as
/// soon as every vertex is within `prefitStopFraction` (0.7) of the tolerance of its arc-length
/// counterpart: it only has to be judged (wavy: 768 -> 645 evaluations per strand; 1.77 %
/// without). The piece kept is then polished by a short Nelder–Mead on Eq. 5 itself
/// (`polishEvaluations`, 20, from a small simplex), so the result is still the paper's objective,
/// locally; a polish that would push an acceptable piece over `maxError` is undone (Eq. 5 weighs
/// the mean leash, acceptance the maximum). The polish matters at C¹ joints: without it wavy is at
/// 1.95 % with 72 strands over maxError (1.76 % and 23 with it); 30 evaluations gave 1.77 %.
/// `prefitIterations` = 0 restores Nelder–Mead alone.
/// Starts: the strand's curvature and torsion near the fragment's start — kT = mean curvature,
/// alpha = mean torsion / curvature, the frame rolled so its normal is the strand's Frenet normal
/// there — and, for whole fragments, k = 0 and the previous piece's k; the `prefitStarts` with
/// the lowest pre-fit cost are pre-fitted in that order, stopping at the first within `maxError`
/// (the last piece allowed tries `lastPieceStarts`). A candidate of the split search starts from
/// the nearest fit already found.
///
/// Pieces (§5.3): a fragment whose fit's discrete Fréchet distance is within `maxError` of the
/// strand's length is accepted; otherwise the fragment is split. The upper limit of the split is
/// the longest prefix whose fit is acceptable. Candidates are judged by their pre-fits with
/// discreteFrechetWithin (the decision version, which stops early) on the trace grow produces;
/// a candidate that is not the last piece must also end within `acceptEndOffset` (0.7) of the
/// tolerance of its target vertex, since the next piece starts where it ends (without this, wavy
/// 1.86 % with 47 strands over maxError: a piece ending at the edge of the tolerance hands its
/// successor a start it often cannot recover from). Only the chosen candidate is polished.
///
/// Deviation in the search for the upper limit (`forwardSearch`, the default): the paper's
/// reading — the whole fragment, then 60 % of it (`splitFraction`), then bisection towards the
/// minimum fragment — pre-fits long candidates that fail on wavy hair, whose pieces cover a ninth
/// of the strand. The forward search first fits the whole remainder when the strand turns less
/// than `searchTurn` (2 rad) over it (the paper's first fit of a fragment; a pre-fit within
/// `polishMargin` of acceptable is polished before it is judged), else the prefix over which it
/// turns that much; later pieces start from the turning the previous piece's upper limit covered.
/// From an acceptable candidate it gallops up (`searchGrowth`, 1.5, times as long, or the whole
/// remainder), from an unacceptable one down by halves to the minimum fragment, then bisects to
/// `splitResolution`, each candidate warm-started from the nearest fit found. Measured at the same
/// settings otherwise (500 strands, one thread; these comparisons were run before the branchless
/// pre-fit math, which moves wavy by a few hundredths of a percent either way): wavy top-down 1.81 %, 9.01 pieces, 1052
/// evaluations per strand, 228 strands per CPU second; forward 1.76 %, 9.12 pieces, 645
/// evaluations, 627 per CPU second (a gallop of 2: 670 evaluations); curly 1.63 % -> 1.56 %,
/// 374 -> 298 evaluations; straight 226 -> 194 evaluations, 2.75 -> 2.59 pieces but 1.38 % ->
/// 1.49 % (the top-down search cuts straight strands into more, shorter pieces).
/// From the upper limit the split backtracks along the curvature profile, the paper's rule, to
/// the vertex where fragment and fit differ least in curvature (and direction), within the last
/// `backtrackWindow` (40 %) of the piece, never leaving a fragment shorter than `minFragment`
/// (3 % of the strand, and two segments); a fit that ends within `keepOffset` (0.7) of the
/// tolerance of the strand and `keepAngle` (0.3 rad) of its direction keeps its whole length
/// (with the former 0.5 and 0.1 rad the short pieces of wavy hair were cut back nearly always:
/// 10.2 pieces and 32 strands over maxError; without backtracking 1.85 %, 8.56 pieces).
/// Each piece starts at the end of the previous fitted piece with its frame (C¹, as the paper's
/// pieces), so only k — and, with `optimizeRoll`, a roll about the tangent — is fitted after the
/// first. The first piece fits a roll too: the strand's Frenet normal at the root is rarely the
/// normal of the helicoid that generated it (measured before the pre-fit: 1.84 % -> 1.57 % mean
/// error on straight.hair).
///
/// Piece budget: at most `maxPieces` (16) and, with `capByPoints`, (3 n - 10) / 6 for n vertices,
/// so that a fit (9 floats and 6 per piece) is never larger than its points (3 floats a vertex):
/// 13 pieces at 30 vertices, 8 at 21. Each strand takes only the pieces it needs. The last piece
/// allowed takes what remains, however far it strays; a strand that used every piece and still
/// misses maxError is refitted with `relaxFactor` (1.4) times the tolerance, up to `relaxRetries`
/// (2) times, and the closest fit kept (longer pieces, so the budget reaches the tip): wavy at its
/// stored 21 vertices 4.21 % -> 2.80 %, at 2.6 times the evaluations (without the cap: 2.39 % but
/// fits larger than the points, 0.98x); at 30 vertices it rarely triggers.
///
/// Measured (vdbhair_benchmark --sections fit, 2 threads, best of 3, strands resampled to 30
/// vertices unless noted; mean / p95 discrete Fréchet error relative to length, pieces,
/// evaluations per strand, strands/s; wall-clock rates vary ±30 % or more with other load;
/// "before" is the previous top-down search with at most 8 pieces, on the same rows):
///   straight 1.50 % / 1.96 %, 2.60 pieces, 196, 1671/s   (before: 1.53 %, 1239/s)
///   straight 16 vertices (as stored) 1.64 % / 2.23 %, 3.44 pieces, 326, 2424/s
///   wavy     1.78 % / 2.00 %, 9.20 pieces, 651, 1278/s   (before: 3.13 % / 5.88 %, 7.80, 1076, 411/s)
///   wavy 21 vertices (as stored) 2.78 % / 3.84 %, 7.66 pieces, 1324, 803/s   (before: 3.62 %, 552/s)
///   curly    1.54 % / 1.94 %, 4.07 pieces, 293, 1566/s   (before: 1.74 %, 712/s)
///   short    1.38 % / 1.93 %, 2.23 pieces, 147, 1921/s   (before: 1.50 %, 1280/s)
/// (on a quiet machine; with another build sharing the host the same binary gave wavy 662/s).
/// Wavy (harolongo: noisy coils, about 20° of turning per segment at 30 vertices and ~600° per
/// strand) needs about 9 pieces for 2 %: with phi = alpha·theta a helicoid cannot hold a helix's
/// constant tilt, so a piece follows a coil for about 60° of turning (3-4 segments), and C¹
/// joints pass each piece's direction error on to the next. Error against pieces (the tolerance
/// varied, 500 strands): maxError 1.5 % -> 1.36 % mean, 10.1 pieces; 2 % -> 1.76 %, 9.1; 2.5 % ->
/// 2.20 %, 8.3; at most 8 pieces (the former cap) 2.41 %. The former minimum fragment of 8 % of
/// the strand was what held it back before (2.45 % with it, everything else as now).
/// Measured and not kept: pieces of one segment (more pieces, no lower error), one-vertex
/// resolution of the search (1.78 %, 662 evaluations), a first candidate from 1 rad of turning
/// (1.76 % but p95 2.11 %), a midpoint pre-fit trace (see above), pre-fitting later pieces' first
/// candidate from a single start (more strands over maxError), a Jacobian by forward-mode
/// automatic differentiation (one trace in dual numbers instead of five: the same errors, but a
/// dual trace costs about four plain ones, so only 4 % fewer instructions for 150 lines), and
/// refreshing the Broyden Jacobian after three rejected steps instead of two (more strands over
/// maxError).
/// Kept fits have kT >= 0: a negative kT is flipped with a half-turn roll of the frame, the same
/// curve (§3's sign symmetry; with Eq. 1 as printed it is a half turn about E_T).
///
/// Step convergence (issue 19): a fit must be a streamline, not an artefact of the step it was
/// traced with. Eq. 1 has a singular axis (Helicoid::axisDistance) about which theta turns like
/// a vortex, 1/r per unit length at distance r; with kN < 0 the flow spirals onto it. The bound
/// on k above keeps it 4 steps away at a piece's root only, and the optimizer found pieces whose
/// trace at the scene's step h passed within a step of it, turning theta by 2-2.7 rad in one RK4
/// step: they matched the strand at h, and regrown at h/4 or h/16 0.4-4 % of strands changed by
/// more than twice their error (up to 100 % of their length). Now (`axisClearance`, 2 steps,
/// kAxisClearanceSteps): within() accepts a piece only if its trace at h keeps that distance at
/// every step; Eq. 5 adds a penalty below it (the objective's trace) and the pre-fit a residual
/// (`prefitAxisWeight`, at the vertices), so that neither settles on what acceptance refuses.
/// Pieces kept without acceptance (the last piece allowed, a fragment with no acceptable
/// candidate) are not checked: most are streamlines still; instead every fit is traced at h/4 too
/// (fitStepDeviation, reported as `stepDeviation`) and one that moves by more than
/// `stepDeviationLimit` (0.1) of the tolerance is refitted with every kept piece's curvatures
/// scaled down until it keeps its distance, the better-converged fit kept. Why the distance
/// rather than comparing traces at h and h/4 for every candidate: an RK4 trace 2 steps from the
/// axis or more agrees with the trace at h/16 to 3e-5 of its length (tested on seeded pieces), so
/// one cheap test per step replaces a four times finer trace per candidate.
/// Measured (scripts/fit_step_table.py, up to 2,000 strands; mean error as reported / regrown at
/// h/16, strands that change by more than 2x or exceed 10 % at h/4 or h/16), at 30 vertices:
///   wavy 1.78 % / 2.57 %, 67 flagged -> 1.75 % / 1.75 %, none; straight 1.50 / 1.67 %, 18 ->
///   1.50 / 1.50 %, none; curly 1.54 / 1.78 %, 4 -> 1.60 / 1.60 %, none; short 1.38 / 1.46 %,
///   7 -> 1.36 / 1.36 %, none; ponytail 1.42 / 1.50 %, 6 -> 1.43 / 1.43 %, none;
/// as stored (1,000 strands): wavy 21 vertices 2.79 % / 3.40 %, 28 -> 2.75 / 2.75 %, none;
///   straight 16 vertices 1.61 / 1.78 %, 4 -> 1.66 / 1.66 %, none.
/// Clearances measured: 4 steps (at 30 vertices wavy 1.69 %, straight 1.52 %, curly 1.62 %, but
/// 10.5 pieces on wavy instead of 9.2, and as stored wavy 3.26 %, straight 1.84 %: the margin
/// costs sharp turns at coarse steps); 1 step (as stored wavy 2.82 %, straight 1.63 %). With 4
/// steps: without the pre-fit residual wavy 1.80 % and 2 strands still flagged, a weight of 0.1
/// 1.73 %, 0.3 1.69 %; scaling down every unaccepted piece near the axis instead of refitting only
/// unconverged fits 1.88 % (most such pieces are streamlines).
#pragma once

#include <vdbhair/helicoid/Helicoid.h>
#include <vdbhair/helicoid/Scene.h>
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
    double searchGrowth = 1.5;    ///< the forward search's gallop: an acceptable candidate is followed by one this many times as long
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
    int prefitOrder = 3;          ///< the pre-fit traces with Kutta's third-order rule (3) or RK4 (4): 7 % less CPU, the same errors
    bool broyden = true;          ///< pre-fit Jacobians by Broyden updates (else forward differences every iteration)
    int prefitStarts = 2;         ///< starts pre-fitted for a whole fragment, the best by the pre-fit's cost at the start (3: all; measured on wavy: 2.99 % with 2, 3.05 % with 3 at 11 % more evaluations, 3.95 % with 1)
    bool firstGoodStart = true;   ///< stop at the first pre-fit within maxError (else pre-fit every start and keep the best)
    int lastPieceStarts = 4;      ///< starts pre-fitted for the last piece allowed (kept whatever its error)
    double prefitGain = 1e-2;     ///< the pre-fit stops when an iteration lowers its cost by less than this fraction
    double polishMargin = 1.25;   ///< a pre-fit of a whole fragment within this many maxError is polished before it is judged
    double polishStep = 0.05;     ///< Nelder–Mead's initial step after a pre-fit (scaled parameters; 0.5 without)
    double polishTolerance = 1e-3; ///< Nelder–Mead's absolute tolerance on the scaled parameters
    double step = 0.0;            ///< the regrown strands' tracing step (world units); 0: a quarter of the mean segment length
    double axisClearance = kAxisClearanceSteps; ///< a piece is accepted only if its trace stays this many steps from its singular axis (0: no check, the former fitter; see below)
    double prefitAxisWeight = 0.3; ///< pre-fit weight of the residual that keeps the trace axisClearance steps from the singular axis
    double stepDeviationLimit = 0.1; ///< a fit whose trace at a quarter of its step moves by more than this fraction of the tolerance is refitted with every piece clear of its axis
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
    double stepDeviation = 0.0;         ///< fitStepDeviation(): how far the trace at `step` is from the streamline (world units)
    double clearance = 0.0;             ///< least distance of the trace from a piece's singular axis, in steps
};

/// @brief A scene guide that regrows @a fit: its root, frame, pieces and step (no waviness, wisp or
/// fit record).
SceneGuide guideFromFit(const StrandFit& fit);

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

/// @brief Step convergence of a fit: the largest distance (world units) between its trace at its
/// step h and at h / @a refinement, compared at the same arc lengths (every step point of the
/// coarse trace and every piece's end). A fit that is a streamline gives RK4's O(h⁴) error, far
/// below its Fréchet error; a fit that exploits a discretization artefact (a step across a
/// piece's singular axis) changes by a large fraction of its length (issue 19).
/// @param clearance optional: the coarse trace's least distance from a piece's singular axis, in steps.
double fitStepDeviation(const StrandFit& fit, int refinement = 4, double* clearance = nullptr);

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
    double stepDeviationMean = 0.0; ///< mean StrandFit::stepDeviation relative to strand length
    double stepDeviationMax = 0.0;  ///< its maximum
    std::size_t unconverged = 0;    ///< fits whose stepDeviation exceeds stepDeviationLimit · maxError · length
};

/// @brief Summarize @a fits of @a strands (@a errors as from fitStrands: non-empty where a strand
/// was not fitted, and left out); a fit counts as unconverged above @a stepDeviationLimit ·
/// @a maxError of its length (FitParams).
FitSummary summarizeFits(const StrandSet& strands, const std::vector<StrandFit>& fits,
                         const std::vector<std::string>& errors, double maxError,
                         double stepDeviationLimit = FitParams{}.stepDeviationLimit);

} // namespace vdbhair
