/// @file HairComparison.h
/// @brief `vdbhair compare A B`: every measure of strands/Compare.h, the discrete Fréchet distance
/// of strand pairs and the shares of strands passing into a head, for one reference hairstyle A and
/// one candidate B, in one report that the command line and Python print alike (toJson()).
///
/// A is the reference, B the candidate (HairGS's "predicted"): precision is the share of B's
/// oriented points matched in A, recall the share of A's matched in B. The measures that pair
/// strand i of A with strand i of B (Perm's errors, Fréchet) need equal strand counts and are left
/// out otherwise (HairComparison::paired).
#pragma once

#include <vdbhair/Parameters.h>
#include <vdbhair/strands/Compare.h>
#include <vdbhair/strands/StrandSet.h>

#include <nlohmann/json.hpp>

#include <cstddef>
#include <string>
#include <vector>

namespace vdbhair {

class HeadObstacle;

struct CompareParams
{
    /// The files' unit in metres (0.01: centimetres, 1: metres); 0: unknown. HairGS's thresholds
    /// are millimetres: with an unknown unit the oriented-point measures need @a thresholds in file
    /// units, and are left out without them.
    double metersPerUnit = 0.0;
    /// Oriented-point thresholds as a person gives them (`2:20`): distances in millimetres when
    /// metersPerUnit > 0, else in file units; empty: HairGS's four (hairGsThresholds()) when the
    /// unit is known.
    std::vector<OrientedThreshold> thresholds;
    /// Directions match either way round (a strand stored tip first still matches).
    bool bidirectional = false;
    static constexpr std::size_t kMinSamples = 3;  ///< samples's least: a curvature needs three points

    /// Points per strand for the strand-pair measures (Perm: 100), at least kMinSamples.
    std::size_t samples = 100;
    /// Pair strand i of A with strand i of B when the counts agree (a retrace, a reconstruction,
    /// an edit); false for hairstyles whose strands do not correspond (a synthesis).
    bool pairStrands = true;

    /// @throw ValueError naming the parameter, its value and the rule.
    void validate() const;
};

/// @brief compare's parameters declared once (vdbhair/Parameters.h): the unit (by name or its
/// length in metres), the oriented-point thresholds (`D:ANGLE` text, repeated), the direction rule,
/// the strand-pair samples and the pairing; the command's options, `--help`, Python's keywords and
/// docs/cli.md's table are made from it.
const ParamTable<CompareParams>& compareParameters();

struct HairComparison
{
    std::size_t strandsA = 0, strandsB = 0, verticesA = 0, verticesB = 0;
    double metersPerUnit = 0.0;
    /// At each threshold (distances in file units); empty when not measured (see CompareParams).
    std::vector<OrientedMatch> oriented;
    ChamferDistances chamfer;
    /// Strand i of A against strand i of B (only when the counts agree).
    bool paired = false;
    StrandPairErrors perm;
    /// #S discrete Fréchet distance between the strands, both resampled to CompareParams::samples
    /// points by arc length, over the length of A's strand (0 for a strand of zero length).
    std::vector<double> frechet;
    double frechetMean = 0.0, frechetP95 = 0.0, frechetMax = 0.0;
    /// The share of B's strands that leave A's hair volume (countStrandsLeavingVolume() at
    /// volumeVoxel, A's suggested voxel size): spikes and flares.
    double leavingVolume = 0.0, volumeVoxel = 0.0;
    /// With a head: the shares of A's and of B's strands that pass into it (countStrandsEnteringHead()).
    bool headMeasured = false;
    double enteringHeadA = 0.0, enteringHeadB = 0.0;
};

/// @brief Compare @a b (candidate) with @a a (reference); @a head may be null. In parallel,
/// identical for any thread count.
/// @throw ValueError for bad @a params or a hairstyle without segments.
HairComparison compareHairstyles(const StrandSet& a, const StrandSet& b, const CompareParams& params,
                                 const HeadObstacle* head = nullptr, bool threaded = true);

/// @brief How a verb measures its output against the hairstyle it started from (refine --measure,
/// synth and transfer --measure): compareHairstyles() at @a reference's unit and HairGS's
/// thresholds, with @a head when it is set and not empty; strands paired by index only when
/// @a corresponding (the output is the reference's strands, moved).
HairComparison measureAgainst(const StrandSet& reference, const StrandSet& output, const HeadObstacle* head = nullptr,
                              bool corresponding = true);

/// @brief The comparison in one line for a verb's text report: Chamfer, F1 at the first threshold,
/// the paired errors when the strands pair up, the share leaving the reference's volume; what was
/// left out for want of a unit is said.
std::string summaryLine(const HairComparison& c);

/// @brief The report as JSON: the same keys from the command line (`compare --json`) and Python
/// (`vdbhair.compare()`); per-strand values are left out (they go to a file or to NumPy).
nlohmann::json toJson(const HairComparison& c);

} // namespace vdbhair
