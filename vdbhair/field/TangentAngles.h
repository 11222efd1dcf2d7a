/// @file TangentAngles.h
/// @brief How well strands follow a vector field: the mean angle between their tangents and the
/// field's direction (the report of `retrace` and `refine`, before and after).
#pragma once

#include <vdbhair/strands/StrandSet.h>

#include <openvdb/Grid.h>

#include <cstddef>

namespace vdbhair {

/// @brief Mean angle in degrees between the strands' unit tangents and the field's direction at
/// their vertices, over the vertices where the field is defined and does not vanish.
/// @param[out] counted optional number of vertices that entered the mean
/// @throw TypeError for a grid that is not vec3s or vec3d.
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
/// @throw TypeError for a grid that is not vec3s or vec3d (as meanTangentAngleDeg()).
TangentAngles meanTangentAnglesDeg(const StrandSet& before, const StrandSet& after, const openvdb::GridBase& field,
                                   bool threaded = true);

} // namespace vdbhair
