/// @file StrandStats.h
/// @brief Histograms of a hairstyle's shape, what dataset papers tabulate: strand length, total
/// turning per strand, curvature per vertex and vertices per strand (`vdbhair info --stats`).
#pragma once

#include <vdbhair/Parameters.h>
#include <vdbhair/strands/Measures.h>
#include <vdbhair/strands/StrandSet.h>

#include <cstddef>
#include <vector>

namespace vdbhair {

/// Bins per histogram unless asked otherwise: coarse enough that 5-strand guide sets still show a shape.
constexpr std::size_t kDefaultHistogramBins = 10;

/// The parameters of computeStrandStatistics().
struct StrandStatsParams
{
    static constexpr std::size_t kMaxBins = 10000;
    std::size_t bins = kDefaultHistogramBins;  ///< per histogram, 1 to kMaxBins
};

/// @brief The statistics' parameters declared once (vdbhair/Parameters.h): `bins`, with its range.
/// `info`'s `--bins` and Python's `strand_statistics(bins=)` are made from it.
const ParamTable<StrandStatsParams>& strandStatsParameters();

/// @brief Counts in equal-width bins over [lo, hi]: bin b holds the values in
/// [lo + b w, lo + (b+1) w) (the last bin also holds hi), w = (hi - lo) / #bins. Values above hi
/// are counted in `above` (the curvature histogram's hi is a percentile; see StrandStatistics).
struct Histogram
{
    double lo = 0.0, hi = 0.0;
    std::vector<std::size_t> counts;
    std::size_t above = 0;
    std::size_t total() const;
};

/// @brief The histograms and ranges of computeStrandStatistics().
struct StrandStatistics
{
    StrandSummary summary;        ///< counts, bounding box, length and vertices-per-strand ranges
    RangeStats turning;           ///< total turning per strand, degrees
    RangeStats curvature;         ///< per vertex, 1 / world units
    double curvatureP99 = 0.0;    ///< the 99th percentile of the per-vertex curvature
    Histogram length;             ///< per strand, over [min, max] length
    Histogram turningHist;        ///< per strand, over [min, max] turning
    Histogram curvatureHist;      ///< per vertex, over [0, p99]: capture noise makes the maximum an outlier
    Histogram verticesPerStrand;  ///< per strand, over [min, max] count
};

/// @brief Total turning of a polyline: the sum of the angles (radians) between consecutive
/// segments, repeated points skipped. A straight strand turns 0, a full circle 2 pi.
double totalTurning(const Vec3f* points, std::size_t n);

/// @brief The statistics of @a strands with @a bins bins per histogram (curvature as
/// curvatureProfile() gives it, turning as totalTurning()). In parallel; sums in strand order, so
/// the same for any thread count.
/// @throw ValueError if @a bins is outside its declared range (1 to StrandStatsParams::kMaxBins):
/// "computeStrandStatistics: bins 0: must be between 1 and 10000".
StrandStatistics computeStrandStatistics(const StrandSet& strands, std::size_t bins = kDefaultHistogramBins, bool threaded = true);

} // namespace vdbhair
