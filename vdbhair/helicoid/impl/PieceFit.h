/// @file PieceFit.h
/// @brief One piece of a p-helicoid fitted to a fragment of the target (Piuze et al. 2011, §5.2,
/// Eq. 5), and the test a piece must pass to be accepted (§5.3). Internal to the fitter
/// (HelicoidFit.h); docs/fitting.md says why each number is what it is.
#pragma once

#include <vdbhair/helicoid/HelicoidFit.h>
#include <vdbhair/helicoid/impl/FitStarts.h>
#include <vdbhair/helicoid/impl/FitTarget.h>

#include <cstddef>
#include <functional>
#include <vector>

namespace vdbhair {
namespace fit {

class LeastSquaresProblem;

/// Pre-fit weight of the end direction's residual (unit vectors; positions count as fractions of
/// L): the next piece starts with this one's end frame. 0.3, 0.45 and 0.6 measured; 0.45 kept.
constexpr double kEndTangentWeight = 0.45;
/// Pre-fit weight of the residual that keeps the trace axisClearance steps from the singular axis.
constexpr double kPrefitAxisWeight = 0.3;
/// The pre-fit stops when an iteration lowers its cost by less than this fraction.
constexpr double kPrefitGain = 1e-2;
/// Starts pre-fitted for a whole fragment, the best by the pre-fit's cost at the start (1, 2 and
/// 3 measured on wavy; 2 kept).
constexpr int kPrefitStarts = 2;
/// Nelder–Mead evaluations of the polish after a pre-fit (0 and 30 measured; 20 kept).
constexpr int kPolishEvaluations = 20;
/// Nelder–Mead's initial step (scaled parameters) for a polish after a pre-fit ...
constexpr double kPolishStep = 0.05;
/// ... and its absolute tolerance on the scaled parameters (the relative one on f is 1e-3 of it).
constexpr double kPolishTolerance = 1e-3;
/// Nelder–Mead from raw starts (no pre-fit, the paper's method): initial step and tolerance.
constexpr double kSearchStep = 0.5;
constexpr double kSearchTolerance = 1e-4;
/// A piece before the last is accepted only if it also ends within this fraction of the tolerance
/// of its target vertex: the next piece starts where it ends.
constexpr double kAcceptEndOffset = 0.7;

/// @brief The helicoid of scaled parameters @a x (dims 4 or 5: (kT L, kN L, kB L, alpha[, roll]))
/// for a fragment of length @a L, rooted at @a p0 with frame @a q (rolled by x[4]).
Helicoid scaledHelicoid(const double* x, std::size_t dims, double L, const Vec3d& p0, const FrameD& q);

/// @brief The piece of scaled parameters @a x over length @a L.
HelicoidPiece scaledPiece(const std::vector<double>& x, double L);

/// @brief How fitPiece() runs.
struct PieceFitOptions
{
    StartOptions starts;          ///< which starts (FitStarts.h)
    int startsToRun = 0;          ///< starts pre-fitted, the best first by the pre-fit's cost (0: kPrefitStarts)
    double prefitStop = 0.0;      ///< a pre-fit stops once every vertex is within this distance (world units) of its arc-length counterpart (0: never)
    /// optional: a pre-fit it accepts ends the search among the starts (the starts in order; not the last one run)
    std::function<bool(const std::vector<double>&)> accept;
};

/// @brief Fits pieces to fragments of one target strand. Pieces are chained (and regrown) with
/// RK4 at the scene's step; Eq. 5 traces the same streamlines at four times that step, about one
/// point per target vertex.
/// @warning Not thread-safe (scratch buffers): one per strand.
class PieceFitter
{
public:
    /// @param step the scene's step (world units)
    PieceFitter(const FitTarget& target, const FitParams& params, double step);

    const FitTarget& target() const { return mTarget; }
    const FitParams& params() const { return mParams; }
    double step() const { return mStep; }
    double evalStep() const { return mEvalStep; }
    /// Evaluations of Eq. 5 and of the pre-fit's residuals so far.
    std::size_t evaluations() const { return mEvaluations; }

    /// @brief Fit a piece to the fragment [start.a, @a b] from start.p0 with frame start.q (fixed;
    /// a roll is fitted with params.optimizeRoll). With a pre-fit (params.prefitIterations > 0):
    /// Levenberg–Marquardt on the pre-fit's residuals from the best-ranked starts, stopping at the
    /// first the options accept; the result is not polished (polish()). Without: Eq. 5 at every
    /// start, then Nelder–Mead from the best (params.maxEvaluations).
    /// @return scaled parameters (by this fragment's length)
    std::vector<double> fitPiece(const PieceStart& start, std::size_t b, const PieceFitOptions& options);

    /// @brief Polish a pre-fit @a x of [start.a, @a b]: a short Nelder–Mead on Eq. 5 (kPolishEvaluations).
    void polish(std::vector<double>& x, const PieceStart& start, std::size_t b);

    /// @brief Whether the fit @a x of [start.a, @a b], as grown (RK4 at the scene's step), is
    /// acceptable within @a eps (world units): it keeps params.axisClearance steps from its
    /// singular axis at every step, ends within kAcceptEndOffset · eps of vertex b (unless b is
    /// the last vertex), and its discrete Fréchet distance to the fragment is at most eps.
    bool acceptable(const PieceStart& start, std::size_t b, const std::vector<double>& x, double eps);

    /// @brief Eq. 5, scale-free: the Fréchet coupling's mean leash over L (the end point counted
    /// again), plus λ times the turns of the piece, plus a penalty below params.axisClearance.
    double objective(const std::vector<double>& x, const PieceStart& start, std::size_t b);

    /// @brief The points of the piece @a x over length @a L from (@a p0, @a q), RK4 at step @a h
    /// (the same steps and arithmetic as tracePHelicoid()).
    /// @return the trace's least distance from the piece's singular axis, in scene steps
    double tracePoints(const std::vector<double>& x, double L, const Vec3d& p0, const FrameD& q, double h, std::vector<Vec3d>& out) const;

    /// @brief tracePHelicoid() of the piece @a x over length @a L from (@a p0, @a q) at step @a h, RK4.
    void tracePiece(const std::vector<double>& x, double L, const Vec3d& p0, const FrameD& q, double h, HelicoidTrace& out) const;

    /// Scratch points for tracePoints() (valid until the next call of any member).
    std::vector<Vec3d>& scratchPoints() { return mPoints; }

private:
    class PrefitProblem;

    /// The target's vertices a..b densified to one spacing, kept while the same fragment is asked for.
    struct DenseFragment
    {
        std::vector<Vec3d> pts;
        std::size_t a = ~std::size_t(0), b = 0;
        const std::vector<Vec3d>& get(const FitTarget& target, std::size_t first, std::size_t last, double spacing);
    };

    double axisPenalty(double clearance) const;
    double prefitFrom(LeastSquaresProblem& problem, std::vector<double>& x) const;
    void minimize(std::vector<double>& x, const PieceStart& start, std::size_t b, double initialStep, double tolerance, int evaluations);

    const FitTarget& mTarget;
    const FitParams& mParams;
    double mStep;      ///< the scene's step
    double mEvalStep;  ///< Eq. 5's step: four scene steps
    std::size_t mEvaluations = 0;
    std::vector<Vec3d> mPoints;   ///< scratch: traced points
    std::vector<Vec3d> mPrefitTrace;  ///< scratch: the pre-fit's trace
    DenseFragment mDenseExact;    ///< at the scene's step
    DenseFragment mDense;         ///< at Eq. 5's step
};

} // namespace fit
} // namespace vdbhair
