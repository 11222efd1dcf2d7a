/// @file Refine.h
/// @brief The vector-field refinement of Wang et al. 2009, §5.3: estimate the robust tangent
/// field of a hairstyle, retrace every strand from its root for its own length, and repeat from
/// the coarsest level to the finest (voxel size h·2^(levels-1) down to h).
#pragma once

#include <vdbhair/field/StreamlineTracer.h>
#include <vdbhair/field/TangentField.h>

#include <vector>

namespace vdbhair {

struct RefineParams
{
    FieldParams field;  ///< field.voxelSize is the finest level's; 0 picks suggestVoxelSize()
    int levels = 1;
    TraceParams trace;  ///< trace.step = 0: half of each level's voxel size
};

struct RefineResult
{
    StrandSet strands;                 ///< the refined hairstyle (input vertex counts)
    std::vector<TangentField> fields;  ///< element l: level l (0 the finest), the field the strands were traced through
    TraceStats stats;                  ///< of the last (finest) retrace
    double angleBefore = 0.0;          ///< meanTangentAngleDeg(input, finest field)
    double angleAfter = 0.0;           ///< meanTangentAngleDeg(output, finest field)
    double meanDisplacement = 0.0;     ///< meanVertexDisplacement(input, output)
    double voxelSize = 0.0;            ///< the finest voxel size used
};

/// @brief A voxel size for a hairstyle with no better information: twice the mean segment length
/// (so a voxel holds a couple of vertices of every strand through it), and never so small that
/// the bounding box would exceed 2048 voxels on a side.
double suggestVoxelSize(const StrandSet& strands);

/// @throw as estimateTangentField() and retraceStrands(); ValueError for levels outside [1, 16].
RefineResult refineStrands(const StrandSet& strands, const RefineParams& params, bool threaded = true,
                           openvdb::util::NullInterrupter* interrupter = nullptr);

} // namespace vdbhair
