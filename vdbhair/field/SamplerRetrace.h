/// @file SamplerRetrace.h
/// @brief Retracing a hairstyle through any sampler of the streamline engine (Streamline.h):
/// every strand restarts at its own root and is traced for its own length (Wang et al. 2009,
/// §5.3), one streamline at a time with traceStreamline(), written out at the input's arc
/// lengths (writeAtArcLengths()) or at every step. retraceHelicoidField() is this over a helicoid
/// field; retraceStrands() with TraceKernel::Scalar is this over a vector grid (its default, the
/// lane kernel, is the fast path of the same rules).
#pragma once

#include <vdbhair/field/Streamline.h>
#include <vdbhair/strands/StrandSet.h>

#include <openvdb/util/NullInterrupter.h>

#include <string>
#include <vector>

namespace vdbhair {

/// @brief Retrace @a in through the samplers @a makeSampler() returns (one per task; a sampler
/// need not be thread-safe) with step @a step (world units, resolved) and a margin of
/// params.margin voxels of @a voxelSize. The output keeps the defaults, root UVs and strand ids,
/// and in RetraceVertices::Input mode the per-vertex attributes of the vertices each strand keeps.
/// Results do not depend on the thread count.
/// @param[out] reasons #S stop reasons
/// @param[out] steps #S steps taken
/// @param what the progress stage's name
/// @throw InterruptedError ("<where>: interrupted") when @a interrupter stops the work.
template<typename MakeSamplerT>
void retraceWithSampler(const StrandSet& in, const TraceParams& params, double step, double voxelSize,
                        const MakeSamplerT& makeSampler, StrandSet& out, std::vector<StopReason>& reasons,
                        std::vector<std::size_t>& steps, bool threaded, openvdb::util::NullInterrupter* interrupter,
                        const char* what, const std::string& where);

/// @brief Assemble the output of a retrace from each strand's vertices @a traced (#S), keeping
/// @a in's attributes as retraceWithSampler() says.
void assembleRetrace(const StrandSet& in, bool inputMode, const std::vector<std::vector<Vec3f>>& traced, StrandSet& out);

} // namespace vdbhair

#include <vdbhair/field/impl/SamplerRetraceImpl.h>
