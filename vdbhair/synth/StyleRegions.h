/// @file StyleRegions.h
/// @brief A hairstyle's signature per scalp region (issue 49): what global statistics miss about
/// fringes, partings, layers and curls, measured the same way on an example and on what synth,
/// transfer or comb made from it, so that the report sets each figure of the output beside the
/// example's.
///
/// **Regions.** Every strand belongs to the region of its root, by the root's direction from the
/// head's centre in a frame (RegionFrame) of the head's up axis and its front: the *crown* above
/// 50° of elevation; below it, the *fringe* within 60° of the front, the *back* beyond 120° of
/// it, and the *sides* between. The front, where a hairstyle has no data to say it, is found from
/// the example's roots: the hairline is highest at the forehead (lowest at the nape, between at
/// the ears), whatever the parting or the sweep, so the front is where the first harmonic of the
/// hairline's height (the lowest root below the crown in each 15° sector of azimuth, fitted by
/// least squares) peaks; the output is measured in the example's frame.
///
/// **Figures** (RegionFigures), lengths in head radii: the share of all strands rooted in the
/// region; the 25th, 50th and 75th percentiles of strand length (layers); the share of strands that
/// *lift*, whose highest vertex rises more than 0.1 head radii above their root along up (fringes
/// swept up, volume at the crown); the mean turning per unit length (radians per head radius);
/// the curl amplitude, the mean over the strands' pieces of about a head radius (each at least
/// 0.6 head radii) of the RMS distance of a piece from its own centre line (a local quadratic fit,
/// Gaussian weights of σ 0.25 head radii: curls, not the strand's overall bend nor its lying on
/// the head, at one scale whatever the strands' lengths; StyleRegions.cc, kCurlSigma, says what it
/// keeps); the *flow*,
/// the mean over the strands of the unit direction in which each leaves its root (from the root
/// to the point half a head radius along it, or its tip, in the head's tangent plane at the
/// root), as its part *down* the head (along the meridian, away from the crown) and its part
/// *around* it (positive about up by the right-hand rule: counter-clockwise seen from above), so
/// that a fringe swept to one side, a parting or hair combed back differ from hair that falls
/// (a region's flow is shorter than 1 as its strands leave their roots in less agreement); and,
/// with a head, the share of vertices inside it (deeper than headTolerance(), refine --head's
/// rule).
#pragma once

#include <vdbhair/Types.h>
#include <vdbhair/strands/StrandSet.h>

#include <nlohmann/json.hpp>

#include <array>
#include <string>

namespace vdbhair {

enum class StyleRegion { Crown = 0, Fringe, Sides, Back };
constexpr int kStyleRegions = 4;
const char* styleRegionName(StyleRegion r);

/// The head frame regions are measured in.
struct RegionFrame
{
    Vec3d center{0.0};
    Vec3d up{0.0, 1.0, 0.0};     ///< unit
    Vec3d front{0.0, 0.0, 1.0};  ///< unit, perpendicular to up
    double radius = 1.0;         ///< the head's radius: the unit of lengths
};

/// @brief The frame of a head (@a center, @a up, @a radius) whose front is where the hairline of
/// @a strands' roots is highest (see above).
RegionFrame regionFrameFromRoots(const StrandSet& strands, const Vec3d& center, const Vec3d& up, double radius);

/// @brief The region of a root.
StyleRegion regionOf(const RegionFrame& frame, const Vec3d& root);

struct RegionFigures
{
    std::size_t strands = 0;
    double share = 0.0;                             ///< of all strands
    double lengthP25 = 0.0, lengthP50 = 0.0, lengthP75 = 0.0;  ///< head radii
    double lift = 0.0;                              ///< share of the region's strands that lift
    double turning = 0.0;                           ///< mean radians per head radius
    double curlAmplitude = 0.0;                     ///< head radii
    double flowDown = 0.0, flowAround = 0.0;        ///< mean unit direction leaving the root (see above)
    double insideHead = -1.0;                       ///< share of the region's vertices; -1: no head
};

struct StyleRegions
{
    RegionFrame frame;
    std::array<RegionFigures, kStyleRegions> regions;
};

class HeadObstacle;

/// @brief The figures of every region of @a strands in @a frame; the vertices inside @a head
/// (signed distance below 0) when it is given and not empty.
StyleRegions measureStyleRegions(const StrandSet& strands, const RegionFrame& frame, const HeadObstacle* head = nullptr,
                                 bool threaded = true);

/// @brief The curl amplitude of RegionFigures over all of @a strands (head radius @a radius),
/// measured in pieces of about @a piece head radii (0: one): the mean over the pieces, 0 when
/// there are none. Two hairstyles measured in pieces of one length compare alike, whatever the
/// lengths of their strands (transfer's report: DETAILS' median strand length, medianCurlPiece()).
double meanCurlAmplitude(const StrandSet& strands, double radius, double piece = 0.0);

/// @brief The median length, in head radii, of the strands of @a strands long enough to have a
/// curl amplitude (a head radius when there are none).
double medianCurlPiece(const StrandSet& strands, double radius);

/// @brief Example and output side by side: {"frame": {...}, "crown": {"share": {"example": a,
/// "output": b}, ..., "flow": {"example": [down, around], "output": [...]}, "flow_difference":
/// the distance between the two flows}, ...} (null where a region has no strands).
nlohmann::json toJson(const StyleRegions& example, const StyleRegions& output);

/// @brief The report of synth and transfer: @a example and @a output measured in one frame (the
/// head's @a center, @a up and @a radius, the example's front), as toJson() sets them side by
/// side; @a text, if given, receives summaryLines().
/// @param front the head's front, or (0, 0, 0) to find it from @a example's hairline
nlohmann::json compareStyleRegions(const StrandSet& example, const StrandSet& output, const Vec3d& center, const Vec3d& up, double radius,
                                   const HeadObstacle* head, std::string* text = nullptr, const Vec3d& front = Vec3d(0.0));

/// @brief One line per region for a text report ("crown: 31 % of strands (example 28 %), length
/// p50 1.2 (1.3), lift 40 % (45 %), ...").
std::string summaryLines(const StyleRegions& example, const StyleRegions& output, const std::string& indent = "  ");

} // namespace vdbhair
