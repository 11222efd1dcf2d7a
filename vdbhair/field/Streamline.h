/// @file Streamline.h
/// @brief The streamline engine: one integrator over a sampler concept, the stop rules, the
/// margin, the arc-length write-out and the stop statistics, shared by every place that traces
/// (retracing through a vector grid or a helicoid field, helicoid growth, slice streamlines).
///
/// As OpenVDB's `tools/VelocityFields.h` separates the field, its sampler and the integrator,
/// the engine is templated over a *sampler*: any type with
///
///     SampleStatus direction(const Vec3d& worldPos, Vec3d& unitDir);
///
/// returning the unit direction of the field at a world point (Ok), or why there is none: the
/// point is outside the field (Left: no active corner of its cell) or the field vanishes there
/// (Vanished: the blended vector is shorter than the vanish threshold times the active corners'
/// weight). A sampler whose later stages depend on where a step began may also have
///
///     SampleStatus startDirection(const Vec3d& worldPos, Vec3d& unitDir);
///
/// which the integrator calls instead of direction() for the first stage of each step (the
/// analytic helicoid unwraps every stage's theta against theta at the step's start, and moves
/// that reference only there). Samplers (each one per thread; none is thread-safe):
/// - `FieldDirectionSampler` (FieldSampler.h): a VDB vector grid, trilinear over voxel centres,
///   active-aware, through the bricked sampler;
/// - `HelicoidFieldSampler` (helicoid/HelicoidFieldSampler.h): a helicoid field, each active corner
///   predicting a direction by its own helicoid (Piuze et al. 2011, Eq. 1);
/// - `AnalyticHelicoidSampler` (helicoid/AnalyticHelicoidSampler.h): one helicoid, Eq. 1 exactly, with
///   theta unwrapped along the trace;
/// - `ReversedSampler` (below): any sampler traced backwards.
///
/// Integrators (StreamlineIntegrator::advance()): forward Euler (Eq. 3 of Piuze et al., the
/// papers' choice), midpoint RK2, Kutta's third-order rule (RK3: three stages, the fit's pre-fit
/// traces with it, sharing each step's last point's direction as the next step's first) and
/// classical RK4, each stage's direction a unit vector, so a step of length h advances arc length
/// h and step m of a streamline lies at arc length m·step.
///
/// A streamline (traceStreamline()) stops when
/// - it reaches the requested length (the last step is shortened to land on it exactly);
/// - the field vanishes at a stage of a step;
/// - it leaves the field: a stage finds no active corner, and it has already continued straight
///   along its last direction for the margin past the active region (a short linear
///   extrapolation: smoothed strands of noisy hair travel further than the originals and
///   overshoot the tips of the hair volume; margin 0 is the papers' rule, stop at once);
/// - it has taken `maxSteps` steps;
/// - optionally (StageReversal::Stop), a stage of a step points against its first stage: the
///   field reverses within one step (a sink, or the sign flip of a direction field), which counts
///   as vanishing.
///
/// The SIMD lane kernel of retraceStrands() (impl/LaneTracer.h) is this engine's fast path for
/// the common case (forward Euler in an axis-aligned world-space grid); it runs every other step
/// through StreamlineIntegrator and the margin rule below, and a seeded property test holds it to
/// the general path (TraceParams::kernel forces either).
#pragma once

#include <vdbhair/Parameters.h>
#include <vdbhair/Types.h>

#include <algorithm>
#include <cstddef>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace vdbhair {

enum class Integrator { Euler, RK2, RK3, RK4 };

/// @throw ValueError unless "euler", "rk2", "rk3" or "rk4".
Integrator integratorFromName(const std::string& name);
const char* integratorName(Integrator integrator);

enum class StopReason : unsigned char { FullLength, Vanished, LeftField, MaxSteps };

/// What a sampler found at a point (see the file comment).
enum class SampleStatus : unsigned char { Ok, Left, Vanished };

/// The stop reason of a stage that failed with @a status (Left or Vanished).
inline StopReason stopReasonOf(SampleStatus status)
{
    return status == SampleStatus::Left ? StopReason::LeftField : StopReason::Vanished;
}

/// @brief The default integration step, in voxels: half a voxel, so that a streamline samples
/// every cell it crosses at least once (a step of a voxel or more can skip the corner of a cell,
/// and with it a turn of the field). The one place this default lives; resolveStepLength()
/// applies it.
constexpr double kDefaultStepVoxels = 0.5;

/// @brief The default vanish threshold: a streamline stops where the blended direction's length
/// falls below this fraction of the blend's weight (see the file comment). The one place this
/// default lives: TraceParams, ConsistencyParams and the tangent-angle measure use it.
constexpr double kDefaultVanishThreshold = 1e-3;

/// @brief The step in world units: @a step if positive, else kDefaultStepVoxels · @a voxelSize.
/// @throw ValueError "<where>: step <value> must be 0 (half a voxel) or a positive finite length"
/// for a negative or non-finite step (never silently the default).
double resolveStepLength(double step, double voxelSize, const std::string& where);

/// @brief Number of steps of @a step that trace @a length: ceil(length / step) (the last step
/// shortened), 0 for a zero (or non-finite) length.
std::size_t stepCount(double length, double step);

/// @brief The arc lengths of a retrace's input strand, the lengths its output vertices are
/// placed at: each segment's length in float, summed in double (what the lane kernel computes
/// four segments at a time, bit for bit).
/// @param[out] out #n arc lengths, from 0
/// @return the strand's length
double retraceArcLengths(const Vec3f* points, std::size_t n, double* out);

/// @brief Which vertices a retraced strand keeps.
enum class RetraceVertices
{
    Input,  ///< the input strand's vertex count, at the input's arc lengths (a drop-in replacement)
    Steps   ///< every integration step
};

/// @brief Which implementation traces a retrace through a vector grid. For tests and the
/// benchmark: every kernel gives the same strands (the lanes within float rounding of the scalar
/// path, the two lane clones bitwise), and Auto is the fastest the processor runs.
enum class TraceKernel
{
    Auto,        ///< the lanes, with AVX2 where the processor has it
    Scalar,      ///< the general engine, one streamline at a time, in double (traceStreamline())
    LanesSse,    ///< the lane kernel compiled for the x86-64 baseline
    LanesAvx2    ///< the lane kernel's AVX2 clone (LogicError on a processor without AVX2)
};

struct TraceParams
{
    /// world units; 0 picks kDefaultStepVoxels (half a voxel) of the field's voxel size
    double step = 0.0;
    Integrator integrator = Integrator::Euler;
    double vanishThreshold = kDefaultVanishThreshold;  ///< see the file comment; [0, 1)
    std::size_t maxSteps = 0;       ///< 0: as many as the length needs
    int margin = 3;                 ///< voxels a strand may continue straight past the active region (0: none)
    RetraceVertices vertices = RetraceVertices::Input;
    TraceKernel kernel = TraceKernel::Auto;  ///< retraceStrands() only (see TraceKernel)

    static constexpr int kMaxMargin = 16;  ///< voxels

    /// @throw ValueError "<where>: <parameter> <value> must ..." (the parameter by its field
    /// name: step, margin, vanishThreshold) for a negative or non-finite step, a margin outside
    /// [0, kMaxMargin], a vanish threshold outside [0, 1).
    void validate(const std::string& where) const;
};

/// @brief "input" or "steps".
const char* retraceVerticesName(RetraceVertices vertices);
/// @throw ValueError naming @a name and the choices.
RetraceVertices retraceVerticesFromName(const std::string& name);

/// @brief retrace's parameters (Parameters.h): the one declaration the command line, Python and
/// docs/cli.md are made from. Defaults are TraceParams{}'s.
const ParamTable<TraceParams>& traceParameters();

/// @brief retrace's parameters: the trace's and what its report adds.
struct RetraceParams
{
    TraceParams trace;
    /// Also the mean angle between strand tangents and the field before and after (the field
    /// sampled at every input and output vertex).
    bool measure = false;
};

/// @brief retrace's parameters declared once (traceParameters() and the measure switch): the
/// command line's options, Python's retrace() keywords and docs/cli.md's table.
const ParamTable<RetraceParams>& retraceParameters();

/// @brief What happened to every streamline of a retrace.
struct TraceStats
{
    std::size_t strands = 0;
    std::size_t fullLength = 0;
    std::size_t vanished = 0;
    std::size_t leftField = 0;
    std::size_t maxSteps = 0;
    std::size_t steps = 0;  ///< integration steps taken in all

    /// @brief The statistics of #S streamlines' stop reasons and step counts (summed in order).
    static TraceStats count(const std::vector<StopReason>& reasons, const std::vector<std::size_t>& steps);
};

/// @brief Whether a step whose later stage points against its first (negative dot product)
/// stops the streamline (as Vanished). Retracing continues (the papers' rule); slice
/// streamlines of a direction field whose sign is arbitrary stop.
enum class StageReversal { Continue, Stop };

/// @brief The rules of one streamline (traceStreamline()), resolved to world units.
struct StreamlineRules
{
    Integrator integrator = Integrator::Euler;
    StageReversal reversal = StageReversal::Continue;
    double step = 0.0;          ///< world units, > 0
    double marginLength = 0.0;  ///< world units a streamline may continue straight past the field
    std::size_t maxSteps = 0;   ///< 0: as many as the length needs
};

/// @brief The margin rule: whether a step of length @a h that failed with @a status, as step
/// @a k of its streamline (0: the first), continues straight along the last direction, after
/// @a outside world units already travelled past the field in a row. Only leaving the field
/// continues (never a vanishing field, never the first step: there is no last direction).
inline bool continuesPastField(SampleStatus status, std::size_t k, double outside, double h, double marginLength)
{
    return status == SampleStatus::Left && k > 0 && outside + h <= marginLength * (1.0 + 1e-9);
}

/// @brief One step of a streamline through a sampler (see the file comment).
/// @warning Not thread-safe (nor is the sampler): one per thread.
template<typename SamplerT>
class StreamlineIntegrator
{
public:
    StreamlineIntegrator(SamplerT& sampler, Integrator integrator, StageReversal reversal = StageReversal::Continue)
        : mSampler(sampler), mIntegrator(integrator), mReversal(reversal) {}

    /// @brief One step of length @a h (world units) from @a p: Ok and the end point in @a q, or
    /// the status of the first stage that failed (@a q then undefined).
    SampleStatus advance(const Vec3d& p, double h, Vec3d& q);

    /// @brief advance() with the first stage's unit direction @a k1 at @a p already known (a
    /// helicoid trace has it from the frame at p); Euler then samples nothing.
    SampleStatus advanceFrom(const Vec3d& p, const Vec3d& k1, double h, Vec3d& q);

    /// @brief advanceFrom() with the integrator @a I fixed at compile time (the integrator given
    /// to the constructor is ignored): for a hot loop that always takes the same kind of step
    /// (the fit's pre-fit).
    template<Integrator I>
    SampleStatus advanceFrom(const Vec3d& p, const Vec3d& k1, double h, Vec3d& q);

    SamplerT& sampler() { return mSampler; }
    Integrator integrator() const { return mIntegrator; }

private:
    /// Whether stage @a k turns against the first stage @a k1 under StageReversal::Stop.
    bool reversed(const Vec3d& k1, const Vec3d& k) const { return mReversal == StageReversal::Stop && k.dot(k1) < 0.0; }

    SamplerT& mSampler;
    Integrator mIntegrator;
    StageReversal mReversal;
};

/// @brief Trace one streamline from @a root for @a length world units under @a rules:
/// @a points receives the root and the end of every step taken (points[m] at arc length
/// m · rules.step, the last point of a full-length trace at @a length).
/// @return why it stopped.
template<typename SamplerT>
StopReason traceStreamline(SamplerT& sampler, const Vec3d& root, double length, const StreamlineRules& rules,
                           std::vector<Vec3d>& points);

/// @brief The arc-length write-out of a retrace in RetraceVertices::Input mode: the points of a
/// streamline (traceStreamline()) at the input strand's vertex arc lengths @a target (#n, from
/// 0), the root exactly, the tip exactly where the trace reached @a length. A streamline that
/// stopped early keeps the vertices it passed, then the point where it stopped (at least two).
/// @param[out] out the strand's vertices: n for a full-length trace, else at most n
void writeAtArcLengths(const std::vector<Vec3d>& points, double length, double step, StopReason reason,
                       const double* target, std::size_t n, std::vector<Vec3f>& out);

/// @brief The write-out in RetraceVertices::Steps mode: every point, and the root twice where
/// no step was taken.
void writeSteps(const std::vector<Vec3d>& points, std::vector<Vec3f>& out);

/// @brief A sampler traced backwards: the directions of @a SamplerT, negated.
template<typename SamplerT>
class ReversedSampler
{
public:
    explicit ReversedSampler(SamplerT& sampler) : mSampler(sampler) {}
    SampleStatus direction(const Vec3d& worldPos, Vec3d& unitDir)
    {
        const SampleStatus s = mSampler.direction(worldPos, unitDir);
        unitDir = -unitDir;
        return s;
    }

private:
    SamplerT& mSampler;
};

} // namespace vdbhair

#include <vdbhair/field/impl/StreamlineImpl.h>
