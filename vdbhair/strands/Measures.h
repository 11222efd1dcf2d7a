/// @file Measures.h
/// @brief Discrete differential measures of polylines: arc length, unit tangents, curvature,
/// torsion, and a whole-hairstyle summary.
///
/// The estimators are chosen to be exact on circles and second-order accurate on smooth curves
/// (tested against a helix of radius r and pitch c: curvature r/(r²+c²), torsion c/(r²+c²)):
/// - tangent at a vertex: the tangent of the circle through it and its two neighbours;
/// - curvature: the inverse radius of that circle, 2|a×b| / (|a||b||a+b|);
/// - torsion on an edge: the signed angle between the discrete binormals of its end vertices
///   (right-handed positive) over the edge length; at a vertex, the mean of its two edges.
/// All are second-order accurate in the sampling step (tested). Torsion is a third difference
/// of positions and amplifies their float rounding and any capture noise: on finely sampled or
/// noisy strands, resample (Resample.h) to a coarser spacing before reading torsion.
#pragma once

#include <vdbhair/Types.h>
#include <vdbhair/strands/StrandSet.h>

#include <cstddef>
#include <vector>

namespace vdbhair {

/// @brief Length of a polyline of @a n points (world units), summed in double precision.
double polylineLength(const Vec3f* points, std::size_t n);

/// @brief Cumulative arc length at each vertex: #n values, the first 0, the last the length.
void arcLengths(const Vec3f* points, std::size_t n, double* out);

/// @brief Length of every strand (#S values, world units); parallel over strands.
std::vector<float> strandLengths(const StrandSet& strands);

/// @brief Unit tangent at each of the @a n points (root to tip), written to @a out.
/// Repeated points are skipped over; a polyline of zero length gets zero tangents.
void computeTangents(const Vec3f* points, std::size_t n, Vec3f* out);

/// @brief Unit tangent at every vertex of every strand (#V values); parallel over strands.
std::vector<Vec3f> computeTangents(const StrandSet& strands);

/// @brief Curvature (1 / world units) at each of the @a n points; endpoints copy their
/// neighbour. A polyline of two points has curvature 0.
void curvatureProfile(const Vec3f* points, std::size_t n, float* out);

/// @brief Signed torsion (1 / world units) at each of the @a n points; 0 where the binormal is
/// undefined (straight parts), endpoints copy their neighbour.
void torsionProfile(const Vec3f* points, std::size_t n, float* out);

/// @brief min / mean / max of a quantity over strands.
struct RangeStats
{
    double min = 0.0, mean = 0.0, max = 0.0;
};

/// @brief The summary `vdbhair info` prints for strands.
struct StrandSummary
{
    std::size_t strands = 0;
    std::size_t vertices = 0;
    BBox bbox;
    RangeStats length;             ///< world units
    RangeStats verticesPerStrand;
    double metersPerUnit = 0.0;    ///< the unit the file declared (StrandSet::metersPerUnit), 0: none
    char upAxis = 0;               ///< the up axis the file declared (StrandSet::upAxis), 0: none
};

/// @brief Counts, bounding box and the ranges of strand length and vertices per strand.
StrandSummary summarizeStrands(const StrandSet& strands);

} // namespace vdbhair

namespace vdbhair {

/// @brief The strand indices sorted along a Morton (Z-order) curve of their roots, quantized to
/// 2^10 cells per axis of the roots' bounding box (ties keep index order). Processing strands in
/// this order keeps neighbouring strands together, which keeps the grid data they touch in cache.
/// A deterministic function of the roots only.
std::vector<std::uint32_t> spatialOrder(const StrandSet& strands);

/// @brief The same order of points (quantized in single precision): for work on neighbouring points.
std::vector<std::uint32_t> spatialOrder(const std::vector<Vec3d>& points);

/// @brief Mean distance between corresponding vertices of @a a and @a b: each vertex of a
/// strand of @a a against the point of the same strand of @a b at the same arc length (up to
/// the shorter of the two strands). Both sets must have the same strand count.
/// @throw ValueError if the strand counts differ.
double meanVertexDisplacement(const StrandSet& a, const StrandSet& b, bool threaded = true);

} // namespace vdbhair
