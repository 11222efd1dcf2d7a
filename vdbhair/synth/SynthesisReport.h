/// @file SynthesisReport.h
/// @brief How a synthesized hairstyle compares with its example (issue 15's statistics): distances
/// between distributions of per-strand measures, wisp sizes per level, tangent coherence, and
/// whether the output is new rather than a copy.
///
/// Distribution distances are the 1-Wasserstein (earth mover's) distance between the two
/// empirical distributions divided by the example's mean, so 0.1 reads "the distributions differ
/// by 10 % of the example's typical value" whatever the unit. Novelty: every output strand's
/// nearest example strand (among the 8 with the nearest roots, by RMS distance over n_s vertices
/// resampled by arc length) in head radii, against the same measure between an example strand and
/// its nearest *other* example strand: a copy is at 0, a new strand at the example's own spacing.
#pragma once

#include <vdbhair/strands/StrandSet.h>

#include <cstdint>
#include <vector>

namespace vdbhair {

/// @brief The 1-Wasserstein distance between the empirical distributions of @a a and @a b,
/// divided by the mean of @a a (0 when both are empty; the raw distance when a's mean is 0).
double relativeWasserstein(std::vector<double> a, std::vector<double> b);

/// @brief Total turning angle per unit length of every strand (radians per world unit).
std::vector<double> turningPerLength(const StrandSet& strands);

struct NoveltyStats
{
    double outputMedian = 0.0;    ///< median RMS distance of an output strand to its nearest example strand, head radii
    double exampleMedian = 0.0;   ///< median RMS distance of an example strand to its nearest other example strand
    double copies = 0.0;          ///< share of output strands within 0.01 head radii RMS of an example strand
};

/// @param radius the head radius (world units) distances are expressed in
NoveltyStats measureNovelty(const StrandSet& example, const StrandSet& output, double radius, int vertices = 16,
                            bool threaded = true);

/// @brief Mean total turning per unit length of @a strands resampled to @a vertices vertices by arc
/// length (hairstyles stored at different resolutions compare at one; 0 for no strands).
double meanTurningPerLength(const StrandSet& strands, int vertices);

/// @brief Mean total turning per unit length of @a strands resampled at one @a spacing (world
/// units) by arc length (resampleStrandsBySpacing()): hairstyles whose strands differ in length
/// compare at one sample spacing, where a fixed vertex count would undersample the longer ones'
/// curls (0 for no strands).
/// @throw ValueError unless @a spacing is positive and finite.
double meanTurningPerLengthAtSpacing(const StrandSet& strands, double spacing);

/// @brief How far the wisps of @a a lie from those of @a b: for every cluster c with members in
/// both (labelA[s] == c, labelB[s] == c), the mean strand of its members in each (resampled to
/// @a vertices by arc length, averaged vertex by vertex, then smoothed with σ = @a smoothing ×
/// @a vertices, smoothPolyline()), and the discrete Fréchet distance between the two means divided
/// by the length of b's. Transfer keeps BASE's coarse shape and replaces its detail; with the
/// transfer's smoothing this compares exactly the part that should be kept.
std::vector<double> clusterMeanDeviation(const StrandSet& a, const std::vector<std::int32_t>& labelA, const StrandSet& b,
                                         const std::vector<std::int32_t>& labelB, int vertices = 64, double smoothing = 0.0);

/// @brief Sizes of the clusters given by @a label (#N, values in [0, k)).
std::vector<double> clusterSizes(const std::vector<std::int32_t>& label);

} // namespace vdbhair
