/// @file Resample.h
/// @brief Resampling strands by arc length, and smoothing polylines.
#pragma once

#include <vdbhair/strands/StrandSet.h>

#include <cstddef>

namespace vdbhair {

/// @brief Resample a polyline of @a n points to @a count points equally spaced in arc length
/// (root and tip kept exactly). A zero-length polyline gives @a count copies of its root.
/// @param count at least 2
void resamplePolyline(const Vec3f* points, std::size_t n, std::size_t count, Vec3f* out);

/// @brief Every strand resampled to @a verticesPerStrand vertices equally spaced in arc length;
/// per-vertex attributes are interpolated linearly at the same arc lengths.
/// @throw ValueError if @a verticesPerStrand < 2.
StrandSet resampleStrands(const StrandSet& strands, std::size_t verticesPerStrand);

/// @brief Every strand resampled to the vertex count whose equal spacing is nearest to
/// @a spacing (world units): max(2, round(L / spacing) + 1) vertices for a strand of length L.
/// @throw ValueError if @a spacing is not a positive finite number, or if the result would
/// exceed @a maxVertices vertices.
StrandSet resampleStrandsBySpacing(const StrandSet& strands, float spacing,
                                   std::size_t maxVertices = std::size_t(1) << 31);

/// @brief Gaussian smoothing of a polyline of @a n points with a kernel of σ = @a sigma vertices
/// (truncated at 3σ): both ends stay where they are, because the polyline is extended by odd
/// reflection about each end (p(−k) = 2 p(0) − p(k)), which also leaves a straight polyline as it
/// is. @a sigma ≤ 0 copies. @a out may not alias @a points.
void smoothPolyline(const Vec3d* points, std::size_t n, double sigma, Vec3d* out);

} // namespace vdbhair
