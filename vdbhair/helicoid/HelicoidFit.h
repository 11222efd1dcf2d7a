/// @file HelicoidFit.h
/// @brief Fitting p-helicoids to unparameterized strands (Piuze et al. 2011, §5.2-5.3): the
/// public entry points, their options and results.
///
/// One piece (Eq. 5): k minimizes C(h, H(k, Q, p0, L)) + λ|k|, scale-free (C is the Fréchet
/// coupling's mean leash over L, |k| the turns of the piece), pre-fitted by Levenberg–Marquardt
/// on the arc-length correspondence and polished by Nelder–Mead on Eq. 5 itself. Pieces (§5.3):
/// a fragment whose fit is within maxError of the strand's length is accepted, otherwise it is
/// split at the longest acceptable prefix (found by a SplitSearch) and backtracked along the
/// curvature profile. Fits are streamlines: every piece keeps axisClearance steps from its
/// singular axis (issue 19) and is grown with RK4 at the fit's step.
///
/// docs/fitting.md describes the method, each deviation from the paper, the variants that were
/// measured and why the survivors are the defaults. The parts live in impl/: the local solvers
/// (LevenbergMarquardt.h, NelderMead.h), the pre-fit's trace (PrefitTrace.h), the starts
/// (FitStarts.h), the piece fit (PieceFit.h), the split search (SplitSearch.h) and the
/// piecewise fit of one strand (PiecewiseFit.h).
#pragma once

#include <vdbhair/Parameters.h>

#include <vdbhair/helicoid/Helicoid.h>
#include <vdbhair/helicoid/Scene.h>
#include <vdbhair/strands/StrandSet.h>

#include <openvdb/util/NullInterrupter.h>

#include <cstddef>
#include <string>
#include <vector>

namespace vdbhair {

/// @brief How the split of a fragment finds its upper limit, the longest prefix whose fit is
/// acceptable (§5.3; docs/fitting.md).
enum class SplitSearch
{
    /// From a first guess (where the strand has turned as much as the previous piece's limit
    /// covered), galloping up or halving down, then bisection; each candidate warm-started from
    /// the nearest fit found. The default: the same error on wavy hair at 61 % of the evaluations.
    Forward,
    /// The paper's reading: the whole fragment, then 60 % of it, then bisection towards the
    /// shortest fragment. Also what runs without a pre-fit (prefitIterations = 0).
    TopDown
};

struct FitParams
{
    /// Most pieces any strand may have (the upper bound of maxPieces).
    static constexpr int kMaxPieces = 64;

    double maxError = 0.02;       ///< accepted discrete Fréchet distance, as a fraction of the strand length
    double lambda = 1e-3;         ///< regularization weight of Eq. 5 (dimensionless: per turn of the piece)
    int maxPieces = 16;           ///< most pieces per strand, 1 to kMaxPieces (see capByPoints)
    bool capByPoints = true;      ///< also at most (3 n - 10) / 6 pieces for n vertices: a fit never has more floats than its points
    SplitSearch splitSearch = SplitSearch::Forward; ///< how a fragment's split is found (forward needs the pre-fit)
    int relaxRetries = 2;         ///< refits of a strand that used every piece allowed and still misses maxError, each with 1.4 times the tolerance
    bool optimizeRoll = true;     ///< also fit a roll angle for pieces after the first (measured: halves the mean error)
    int maxEvaluations = 300;     ///< Nelder–Mead evaluations per piece without a pre-fit (prefitIterations = 0)
    int prefitIterations = 10;    ///< Levenberg–Marquardt iterations of the pre-fit per start (0: none, Nelder–Mead from the raw starts, the paper's)
    double step = 0.0;            ///< the regrown strands' tracing step (world units); 0: a quarter of the mean segment length
    double axisClearance = kAxisClearanceSteps; ///< a piece is accepted only if its trace stays this many steps from its singular axis (0: no check, the former fitter)
    double stepDeviationLimit = 0.1; ///< a fit whose trace at a quarter of its step moves by more than this fraction of the tolerance is refitted with every piece clear of its axis
    /// Strands of zero length are left out of the scene the front ends make (fitStrands() reports
    /// them either way); false: they are refused
    bool skipDegenerate = false;

    /// Fewest Nelder–Mead evaluations a piece may be given (a 5-parameter simplex needs 6 to start).
    static constexpr int kMinEvaluations = 10;

    /// @throw ValueError naming the first field outside its range as "<where>: <field> <value>: <rule>"
    /// (fitStrand and fitStrands call it; commands call it before reading their input).
    void validate(const char* where) const;
};

/// @brief fit's parameters (Parameters.h), declared once: `fit`, Python's fit() and
/// `reconstruct` (its --max-error) are made from them. Defaults are FitParams{}'s.
const ParamTable<FitParams>& fitParameters();

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
/// @throw ValueError for fewer than 2 distinct points or a zero length, and for maxPieces outside
/// [1, FitParams::kMaxPieces] (named as maxPieces).
StrandFit fitStrand(const Vec3f* points, std::size_t n, const FitParams& params);

/// @brief Fit every strand (in parallel, independent of the thread count); each at its own scale
/// (its own step) unless params.step is given.
/// @param[out] errors optional: #S messages, empty where the strand was fitted; without it the
/// first failure throws.
/// @param interrupter optional progress and Ctrl-C (Progress.h).
/// @throw ValueError for maxPieces outside [1, FitParams::kMaxPieces] (before any work);
/// InterruptedError when the interrupter stops the work.
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
