/// @file RefineReport.h
/// @brief What an artist sees of a refinement, measured against the input hairstyle
/// (docs/fields.md, "Refinement"): whether strands leave the hair, enter the head, lose their curls,
/// reach their length, move, and whether the flow got more coherent.
#pragma once

#include <vdbhair/field/HeadObstacle.h>
#include <vdbhair/field/TangentField.h>
#include <vdbhair/strands/StrandSet.h>

#include <cstddef>
#include <vector>

namespace vdbhair {

struct RefineMeasures
{
    std::size_t strands = 0;
    /// strands with a point (vertices, and points at most half a voxel apart between them)
    /// outside the input's hair volume: the voxels the input's segments pass, dilated by one
    /// voxel (26 neighbours; HairVolume.h, the rule retraceConsistent() holds strands to)
    std::size_t leftVolume = 0;
    std::vector<std::size_t> leftExamples;  ///< the first (lowest) indices of such strands, at most 10
    std::size_t insideHeadBefore = 0;  ///< input vertices strictly inside the head
    std::size_t insideHeadAfter = 0;   ///< output vertices strictly inside the head
    /// median over strands of the mean curvature, output over input: at the vertices, and at an
    /// 8-segment scale (every 8th vertex and the tip; strands of under 10 vertices are skipped)
    double curvatureKeptVertex = 1.0, curvatureKept8 = 1.0;
    /// share of output tips in a voxel holding an input tip, or one of its 26 neighbours
    double tipOccupancy = 1.0;
    std::size_t fullLength = 0;  ///< strands within 0.1 % of their input length
    /// vertex displacement (each output vertex against the input vertex of the same index),
    /// in voxels of the finest level: mean and 95th percentile
    double displacementMean = 0.0, displacementP95 = 0.0;
    /// density-weighted mean of the coherence |Σ ℓT| / Σ ℓ of each hairstyle's own field at the
    /// finest voxel size (TangentField::coherence)
    double coherenceBefore = 0.0, coherenceAfter = 0.0;
};

/// @brief Measure @a output against @a input.
/// @param inputField the input's field at the finest voxel size (its topology is the hair volume)
/// @param params the field parameters of that level (the output's field is estimated with them)
/// @param head the obstacle the counts of vertices inside the head use (empty: counts are 0)
/// @throw ValueError if the two sets differ in strand count.
RefineMeasures measureRefinement(const StrandSet& input, const StrandSet& output, const TangentField& inputField,
                                 const FieldParams& params, const HeadObstacle& head, bool threaded = true);

/// @brief Density-weighted mean coherence of a field (0 for an empty one).
double meanCoherence(const TangentField& field);

} // namespace vdbhair
