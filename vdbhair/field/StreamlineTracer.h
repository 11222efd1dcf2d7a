/// @file StreamlineTracer.h
/// @brief Streamlines through a vector grid, and retracing a hairstyle: every strand restarts at
/// its own root and is traced for its own length (Wang et al. 2009, §5.3).
///
/// Sampling is trilinear over voxel centres (FieldSampler.h); the step follows the unit direction
/// of the sampled vector, so each step advances the given arc length. Integrators: forward Euler
/// (the papers' choice), midpoint RK2 and classical RK4 (each stage's direction normalized).
/// A streamline stops when
/// - it reaches the requested length (the last step is shortened to land on it exactly);
/// - the field vanishes: the blended vector's length over the active corners' weight is below
///   `vanishThreshold` (opposing directions cancel, or zero vectors);
/// - it leaves the field: no corner of the sampling cell is active, and it has already continued
///   straight along its last direction for `margin` voxels past the active region (a short
///   linear extrapolation: smoothed strands of noisy hair travel further than the originals and
///   overshoot the tips of the hair volume; margin 0 is the papers' rule, stop at once);
/// - it has taken `maxSteps` steps.
/// Each stop reason is counted. Streamlines are independent, so results do not depend on the
/// thread count.
#pragma once

#include <vdbhair/strands/StrandSet.h>

#include <openvdb/Grid.h>
#include <openvdb/util/NullInterrupter.h>

#include <cstddef>
#include <string>

namespace vdbhair {

enum class Integrator { Euler, RK2, RK4 };

/// @throw ValueError unless "euler", "rk2" or "rk4".
Integrator integratorFromName(const std::string& name);
const char* integratorName(Integrator integrator);

enum class StopReason : unsigned char { FullLength, Vanished, LeftField, MaxSteps };

/// @brief Which vertices a retraced strand keeps.
enum class RetraceVertices
{
    Input,  ///< the input strand's vertex count, at the input's arc lengths (a drop-in replacement)
    Steps   ///< every integration step
};

struct TraceParams
{
    double step = 0.0;  ///< world units; 0 picks half the field's voxel size
    Integrator integrator = Integrator::Euler;
    double vanishThreshold = 1e-3;  ///< see the file comment
    std::size_t maxSteps = 0;       ///< 0: as many as the length needs
    int margin = 3;                 ///< voxels a strand may continue straight past the active region (0: none)
    RetraceVertices vertices = RetraceVertices::Input;
};

/// @brief What happened to every streamline of a retrace.
struct TraceStats
{
    std::size_t strands = 0;
    std::size_t fullLength = 0;
    std::size_t vanished = 0;
    std::size_t leftField = 0;
    std::size_t maxSteps = 0;
    std::size_t steps = 0;  ///< integration steps taken in all
};

/// @brief Retrace @a strands through the vector grid @a field (Vec3SGrid or Vec3DGrid, in world or
/// scalp space per its metadata): strand i starts at its own root and is traced for its own
/// length. A strand that stops early keeps the part it traced (at least its root twice).
/// Per-strand attributes are kept; per-vertex attributes are kept in RetraceVertices::Input mode.
/// @param[out] reasons optional #S stop reasons
/// @throw TypeError (not a Vec3 grid), ValueError (bad step, threshold), LimitError (a strand that
/// would take more than 2^31 steps: step far too small for its length), InterruptedError.
StrandSet retraceStrands(const StrandSet& strands, const openvdb::GridBase& field, const TraceParams& params,
                         TraceStats* stats = nullptr, std::vector<StopReason>* reasons = nullptr,
                         bool threaded = true, openvdb::util::NullInterrupter* interrupter = nullptr);

/// @brief retraceStrands() into @a out, reusing its storage: its capacity is kept, so repeated
/// retraces (refinement levels, a tool re-running a retrace) write into memory that is already
/// mapped instead of faulting in a fresh output (on a virtual machine, faulting in 77 MB of new
/// pages costs about 40 ms, a third of retracing 100,000 strands on two cores). On an exception
/// @a out holds an unspecified set of strands.
/// @throw as retraceStrands(); ValueError if @a out is @a strands.
void retraceStrandsInto(const StrandSet& strands, const openvdb::GridBase& field, const TraceParams& params, StrandSet& out,
                        TraceStats* stats = nullptr, std::vector<StopReason>* reasons = nullptr, bool threaded = true,
                        openvdb::util::NullInterrupter* interrupter = nullptr);

/// @brief The step retraceStrands() uses for @a params on @a field (resolves step = 0).
double resolveStep(const openvdb::GridBase& field, const TraceParams& params);

/// @brief Mean angle in degrees between the strands' unit tangents and the field's direction at
/// their vertices, over the vertices where the field is defined and does not vanish.
/// @param[out] counted optional number of vertices that entered the mean
double meanTangentAngleDeg(const StrandSet& strands, const openvdb::GridBase& field,
                           std::size_t* counted = nullptr, bool threaded = true);

/// meanTangentAngleDeg() of two sets, e.g. a retrace's input and output.
struct TangentAngles
{
    double beforeDeg = 0.0, afterDeg = 0.0;
    std::size_t countedBefore = 0, countedAfter = 0;  ///< vertices that entered each mean
};

/// @brief meanTangentAngleDeg() of @a before and of @a after against @a field, in one parallel
/// pass that builds the field's bricks once, strand i of both sets together and the strands in
/// spatial order (the report of `retrace`).
TangentAngles meanTangentAnglesDeg(const StrandSet& before, const StrandSet& after, const openvdb::GridBase& field,
                                   bool threaded = true);

/// @brief Mean distance between corresponding vertices of @a a and @a b: each vertex of a
/// strand of @a a against the point of the same strand of @a b at the same arc length (up to
/// the shorter of the two strands). Both sets must have the same strand count.
double meanVertexDisplacement(const StrandSet& a, const StrandSet& b, bool threaded = true);

} // namespace vdbhair
