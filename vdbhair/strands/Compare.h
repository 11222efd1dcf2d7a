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
/// The share of strands leaving a hairstyle's volume is field/HairVolume.h's countStrandsLeavingVolume().
#pragma once

#include <vdbhair/strands/PointGrid.h>
#include <vdbhair/strands/StrandSet.h>

#include <nlohmann/json_fwd.hpp>

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

/// @brief A hairstyle's vertices indexed for the measures below, built once and shared by them:
/// a grid of the vertices (PointGrid.h), each vertex's oriented point (the unit direction of the
/// segment it starts; none for a strand's last vertex or a repeated one), its strand, and each
/// strand's vertices in runs of up to kRun with a bounding sphere (to match against one strand).
/// Refers to @a strands, which must outlive it.
class StrandIndex
{
public:
    static constexpr std::size_t kRun = 8;  ///< vertices a run

    explicit StrandIndex(const StrandSet& strands, bool threaded = true);

    const StrandSet& strands() const { return *mStrands; }
    const PointGrid& grid() const { return mGrid; }
    /// The direction of vertex @a v's segment; zero when it has none.
    const Vec3f& direction(std::size_t v) const { return mDirection[v]; }
    bool oriented(std::size_t v) const { return mDirection[v] != Vec3f(0.f); }
    std::uint32_t strandOf(std::size_t v) const { return mStrandOf[v]; }
    std::size_t orientedPoints() const { return mOrientedPoints; }
    /// The strands in an order along a space-filling curve (by their middle vertex): strands near
    /// in it are near in space, so queries made in this order find the grid's cells in cache.
    const std::vector<std::uint32_t>& spatialOrder() const { return mOrder; }

    /// The runs of strand @a s: [firstRun(s), firstRun(s + 1)); run r holds vertices
    /// [runBegin(r), runBegin(r + 1)) within runRadius(r) of runCentre(r).
    std::size_t firstRun(std::size_t s) const { return mFirstRun[s]; }
    std::size_t runBegin(std::size_t r) const { return mRunBegin[r]; }
    const Vec3d& runCentre(std::size_t r) const { return mRunCentre[r]; }
    double runRadius(std::size_t r) const { return mRunRadius[r]; }

private:
    const StrandSet* mStrands;
    PointGrid mGrid;
    std::vector<Vec3f> mDirection;
    std::vector<std::uint32_t> mStrandOf;
    std::size_t mOrientedPoints = 0;
    std::vector<std::uint32_t> mOrder;
    std::vector<std::size_t> mFirstRun, mRunBegin;
    std::vector<Vec3d> mRunCentre;
    std::vector<double> mRunRadius;
};

struct OrientedMatch
{
    OrientedThreshold threshold;
    double precision = 0.0, recall = 0.0, f1 = 0.0;
    double strandConsistency = 0.0;
};

/// @brief Oriented-point matches as JSON, one object per threshold: distance (file units),
/// angle_degrees, precision, recall, f1, strand_consistency and, with @a metersPerUnit > 0,
/// distance_mm. Every report that carries them (compare, reconstruct) writes them through this.
nlohmann::json toJson(const std::vector<OrientedMatch>& matches, double metersPerUnit);

/// @brief Oriented-point precision, recall, F1 and strand consistency of @a predicted against
/// @a reference at each threshold (see above). In parallel; identical for any thread count.
/// @throw ValueError for a negative or non-finite distance, an angle outside [0, 180], or a
/// hairstyle with no segment.
std::vector<OrientedMatch> matchOrientedPoints(const StrandSet& predicted, const StrandSet& reference,
                                               const std::vector<OrientedThreshold>& thresholds, bool bidirectional = false,
                                               bool threaded = true);
/// @brief The same, of hairstyles already indexed.
std::vector<OrientedMatch> matchOrientedPoints(const StrandIndex& predicted, const StrandIndex& reference,
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
/// @brief The same, of hairstyles already indexed.
ChamferDistances chamferDistances(const StrandIndex& a, const StrandIndex& b, bool threaded = true);

/// @brief For every vertex of @a from, the distance to the nearest vertex of @a to (Chamfer's
/// terms: what `render --color-by error` shows). Exact; identical for any thread count.
std::vector<double> nearestVertexDistances(const StrandIndex& from, const StrandIndex& to, bool threaded = true);

} // namespace vdbhair
