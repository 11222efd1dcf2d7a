/// @file StreamlineTracer.h
/// @brief Retracing a hairstyle through a vector grid: every strand restarts at its own root and
/// is traced for its own length (Wang et al. 2009, §5.3).
///
/// The streamline engine (Streamline.h: integrators, stop rules, margin, write-out) over the
/// grid's FieldDirectionSampler (FieldSampler.h: trilinear over voxel centres, active-aware). Its
/// fast path is the SIMD lane kernel (impl/LaneTracer.h), forward Euler in an axis-aligned
/// world-space grid, eight streamlines at a time; every other step goes through the engine's
/// general integrator. TraceParams::kernel forces either path (tests, benchmark). Each stop
/// reason is counted. Streamlines are independent, so results do not depend on the thread count.
#pragma once

#include <vdbhair/field/Streamline.h>
#include <vdbhair/strands/StrandSet.h>

#include <openvdb/Grid.h>
#include <openvdb/util/NullInterrupter.h>

#include <cstddef>
#include <string>

namespace vdbhair {

/// @brief Retrace @a strands through the vector grid @a field (Vec3SGrid or Vec3DGrid, in world or
/// scalp space per its metadata): strand i starts at its own root and is traced for its own
/// length. A strand that stops early keeps the part it traced (at least its root twice).
/// Per-strand attributes are kept; per-vertex attributes are kept in RetraceVertices::Input mode.
/// @param[out] reasons optional #S stop reasons
/// @throw TypeError (not a Vec3 grid), ValueError (TraceParams::validate(): a negative step, a
/// margin or vanish threshold out of range), LimitError (a strand that would take more than 2^31
/// steps: step far too small for its length), UnsupportedError (TraceKernel::LanesAvx2 on a
/// processor without AVX2), InterruptedError.
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

/// @brief The step retraceStrands() uses for @a params on @a field (resolves step = 0 to
/// kDefaultStepVoxels of the voxel size; resolveStepLength()).
double resolveStep(const openvdb::GridBase& field, const TraceParams& params);

} // namespace vdbhair
