/// @file Reconstruction.h
/// @brief Rebuilding a captured hairstyle from a fraction of its strands (Piuze et al. 2011, §5.4),
/// made measurable: fit p-helicoids to a subset of the strands (the guides, HelicoidFit.h),
/// interpolate new hairs at the roots of all the others (HelicoidInterpolation.h, world frames:
/// captured hair has no scalp normals), and measure every strand against the original by the
/// discrete Fréchet distance relative to its length. The same is done the peers' way
/// (PointInterpolation.h) from the same guides' raw points, so the two can be compared.
///
/// A third way is measured as the baseline both must beat: each strand replaced by its nearest
/// guide (by root), translated to its root.
///
/// Each way is also measured as hair papers measure (Compare.h): HairGS's oriented-point
/// precision, recall and F1 (when the unit is known) and Perm's strand-pair errors.
///
/// Guide strands are reconstructed as their fits (the helicoid way) or as themselves (the points
/// way), so with every strand a guide the helicoid error is the fits' own error and the points
/// error is zero; the statistics are reported over all strands and over the interpolated ones.
/// Both curves are densified to one spacing before measuring (densifyPolyline): the fits' step
/// (a quarter of the strand's mean segment length unless FitParams::step is given), which makes
/// the helicoid error of a guide exactly the error `vdbhair fit` reports for it.
///
/// Selection: `Random` takes round(f · S) strands (at least 1) by a seeded shuffle; `Cluster` runs
/// eight Lloyd iterations of k-means on the roots from that random start and takes, in each
/// cluster, the strand whose root is nearest its centre (guides spread evenly over the scalp; empty
/// clusters are topped up from the random order).
#pragma once

#include <vdbhair/field/HeadObstacle.h>
#include <vdbhair/helicoid/HelicoidFit.h>
#include <vdbhair/helicoid/HelicoidInterpolation.h>
#include <vdbhair/helicoid/PointInterpolation.h>
#include <vdbhair/strands/Compare.h>

#include <openvdb/util/NullInterrupter.h>

#include <cstdint>
#include <string>
#include <vector>

namespace vdbhair {

enum class GuideSelection { Random, Cluster };

struct ReconstructParams
{
    double guideFraction = 0.10;  ///< share of the strands used as guides, in (0, 1] (the paper: 10 %)
    GuideSelection selection = GuideSelection::Random;
    std::uint64_t seed = 0;
    FitParams fit;
    /// Arcs, not interpolation's Fitted: a reconstruction is judged against the captured strands,
    /// which arcs follow far more closely (docs/interpolation.md).
    HelicoidInterpolationParams helicoid = [] {
        HelicoidInterpolationParams p;
        p.blend = HelicoidBlend::Arcs;
        return p;
    }();
    PointInterpolationParams points;
    /// The file's unit in metres (0.01 for centimetres); 0: unknown, and the oriented-point
    /// measures, whose thresholds are in millimetres, are not computed.
    double metersPerUnit = 0.0;
};

/// @brief "random" or "cluster".
const char* guideSelectionName(GuideSelection selection);
/// @throw ValueError naming @a name and the choices.
GuideSelection guideSelectionFromName(const std::string& name);

/// @brief reconstruct's declared parameters (vdbhair/Parameters.h): the guides' share, choice and
/// seed, the interpolation's (helicoidInterpolationParameters(), guideNeighborsParam(),
/// pointInterpolationParameters()), the fits' accepted error (fitParameters()) and the unit.
/// The command line takes the share as a percentage (its own --guides).
const ParamTable<ReconstructParams>& reconstructParameters();

/// @brief Per-strand errors of one method and their statistics (fractions of the strand length).
struct ReconstructErrors
{
    std::vector<double> relative;   ///< #S discrete Fréchet distance / original length
    double mean = 0.0, p95 = 0.0;   ///< over all strands
    double meanInterpolated = 0.0, p95Interpolated = 0.0;  ///< over the non-guide strands (0 if none)
    double seconds = 0.0;           ///< time to build the method's strands (fitting included for helicoids)
    /// HairGS's precision, recall, F1 and strand consistency against the original at its four
    /// thresholds (Compare.h; empty without ReconstructParams::metersPerUnit), all strands
    std::vector<OrientedMatch> oriented;
    /// Perm's root-aligned position error (world units) and curvature error, means over all strands
    double permPosition = 0.0, permCurvature = 0.0;
    /// Of the interpolated (non-guide) strands, the shares that leave the guides' hair volume
    /// (countStrandsLeavingVolume() at ReconstructResult::volumeVoxel) and that pass into the head
    /// (countStrandsEnteringHead(); 0 without a head)
    double leavingVolume = 0.0, enteringHead = 0.0;
};

struct ReconstructResult
{
    std::vector<std::size_t> guides;  ///< strand indices of the guides that were fitted, ascending
    std::size_t unfitted = 0;         ///< selected strands that could not be fitted (zero length): interpolated instead
    StrandSet helicoid, points;       ///< #S reconstructed strands each, in input order
    ReconstructErrors helicoidErrors, pointErrors;
    ReconstructErrors nearestErrors;  ///< the baseline: every strand its nearest guide, translated
    FitSummary fitSummary;
    double fitSeconds = 0.0;
    /// The same shares for the original strands at the interpolated roots: what a reconstruction
    /// is held to (the guides issue: leaving at most 1.5 times this, entering the head at most this plus 1 point)
    double originalLeavingVolume = 0.0, originalEnteringHead = 0.0;
    double volumeVoxel = 0.0;   ///< suggestVoxelSize() of the guides
    bool headMeasured = false;  ///< whether a head was given
};

/// @brief The strands chosen as guides (ascending indices), see above.
/// @throw ValueError for a fraction outside (0, 1] or no strands.
std::vector<std::size_t> selectGuides(const StrandSet& strands, double fraction, GuideSelection selection, std::uint64_t seed);

/// @brief Discrete Fréchet distance of @a b from @a a, both densified to @a spacing (@a b not at
/// all when no segment of it is longer than the spacing and 1e-4 for float rounding), relative to
/// @a a's length (0 for a zero-length @a a). The measure has a floor of about half the spacing
/// where two different vertex sequences sample the same curve (a discrete measure).
double relativeFrechet(const Vec3f* a, std::size_t na, const Vec3f* b, std::size_t nb, double spacing);

/// @brief Reconstruct @a strands from a share of them, both ways (see above). Identical for any
/// thread count.
/// @throw ValueError (bad fraction, no strand could be fitted, bad interpolation parameters),
/// LimitError, InterruptedError.
/// @param head optional: the head the shares entering it are measured against (nothing is pushed out)
ReconstructResult reconstructHairstyle(const StrandSet& strands, const ReconstructParams& params, bool threaded = true,
                                       openvdb::util::NullInterrupter* interrupter = nullptr, const HeadObstacle* head = nullptr);

} // namespace vdbhair
