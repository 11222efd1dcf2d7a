/// @file Compare.h
/// @brief The measures hair reconstruction papers report when they compare a hairstyle with a
/// reference, defined as they define them, so that figures from vdbhair can stand beside theirs.
///
/// **Oriented points** (HairGS, Pan et al. 2025, `loss/metrics.py`): each strand is taken as the
/// start points of its segments, each with its segment's unit direction. A point of A is matched
/// when a point of B lies within distance d and their directions are within angle θ (dot product
/// ≥ cos θ; with `bidirectional`, its absolute value). Precision = matched share of the
/// predicted hair's points (predicted against reference), recall = matched share of the
/// reference's points (reference against predicted), F1 = 2PR / (P + R) (0 when both are 0).
/// Strand consistency (recall's side): for each reference strand, the largest number of its
/// matched points that match one and the same predicted strand (each point counting each predicted
/// strand it matches once), over its point count; the mean over reference strands with points.
/// HairGS reports 2 mm / 20°, 3 mm / 30°, 4 mm / 40° and 4 mm / 90° (hairGsThresholds()).
///
/// **Strand pairs** (Perm, He et al. 2025): strand i of A against strand i of B, both resampled to
/// 100 points by arc length; the position error is the mean distance between corresponding points
/// after moving B's root onto A's (root-aligned), the curvature error the mean absolute difference
/// of the curvature of the circle through each three consecutive points (1/R = 2 sin∠ / chord).
///
/// **Chamfer distance** (point-set papers, hair reconstruction's geometric baseline): the mean over
/// A's vertices of the distance to the nearest vertex of B, and the same from B to A; reported each
/// way and as their mean (the symmetric Chamfer distance with unsquared distances).
///
/// **Leaving the volume** (the guides issue's measure of spikes and flares): a strand leaves a
/// reference's hair volume when one of its points lies outside the voxels the reference's points
/// occupy, dilated by one voxel (its 26 neighbours). A strand's points are its vertices and points
/// at most half a voxel apart on its segments; a point is in the voxel it rounds to (world / voxel).
#pragma once

#include <vdbhair/strands/StrandSet.h>

#include <cstddef>
#include <vector>

namespace vdbhair {

struct OrientedThreshold
{
    double distance = 0.0;      ///< world units
    double angleDegrees = 0.0;  ///< in [0, 180]
};

/// @brief HairGS's four thresholds in metres: 2 mm / 20°, 3 mm / 30°, 4 mm / 40°, 4 mm / 90°.
std::vector<OrientedThreshold> hairGsThresholds();

struct OrientedMatch
{
    OrientedThreshold threshold;
    double precision = 0.0, recall = 0.0, f1 = 0.0;
    double strandConsistency = 0.0;
};

/// @brief Oriented-point precision, recall, F1 and strand consistency of @a predicted against
/// @a reference at each threshold (see above). In parallel; identical for any thread count.
/// @throw ValueError for a negative or non-finite distance, an angle outside [0, 180], or a
/// hairstyle with no segment.
std::vector<OrientedMatch> matchOrientedPoints(const StrandSet& predicted, const StrandSet& reference,
                                               const std::vector<OrientedThreshold>& thresholds, bool bidirectional = false,
                                               bool threaded = true);

struct StrandPairErrors
{
    std::vector<double> position;   ///< #S root-aligned mean position error per strand (world units)
    std::vector<double> curvature;  ///< #S mean absolute curvature difference per strand (1 / world units)
    double meanPosition = 0.0, meanCurvature = 0.0;  ///< over strands
};

/// @brief Perm's strand-pair errors of @a b against @a a, strand i against strand i (see above).
/// A strand of zero length in either counts its resampled points as they are.
/// @param samples points per resampled strand (Perm: 100), at least 3
/// @throw ValueError when the strand counts differ or samples < 3.
StrandPairErrors strandPairErrors(const StrandSet& a, const StrandSet& b, std::size_t samples = 100, bool threaded = true);

struct ChamferDistances
{
    double aToB = 0.0, bToA = 0.0;  ///< mean nearest-vertex distance each way (world units)
    double mean = 0.0;              ///< (aToB + bToA) / 2
    std::vector<double> perStrandA; ///< #A strands: the mean over each strand's vertices of their distance to B
};

/// @brief The Chamfer distances between the vertices of @a a and @a b (see above). In parallel;
/// identical for any thread count.
/// @throw ValueError when either has no vertex.
ChamferDistances chamferDistances(const StrandSet& a, const StrandSet& b, bool threaded = true);

/// @brief The number of @a strands that leave the hair volume of @a reference at @a voxel (see
/// above). In parallel; identical for any thread count.
/// @throw ValueError for a voxel that is not positive and finite, or one so small that a segment
/// would take more than 2^24 points.
std::size_t countStrandsLeavingVolume(const StrandSet& strands, const StrandSet& reference, double voxel, bool threaded = true);

} // namespace vdbhair
