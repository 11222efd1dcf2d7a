/// @file PointInterpolation.h
/// @brief New hair between guides by blending the guides' own *points*, the way production tools
/// do it (Blender's Interpolate Curves node, Houdini's Hair Generate), with the three things real
/// grooms need on top: groups, likeness of shape, and the head. It is `interpolate`'s and
/// `reconstruct`'s default, because on real hair it measures better than blending helicoid
/// parameters (docs/interpolation.md).
///
/// For a new root x̃:
/// 1. **Group.** Guides blend only with guides of their group (partings, layers, regions): the
///    root's own group id if it has one, else the group of the guide nearest it. Without group
///    ids every guide is in one group.
/// 2. **Weights.** The K nearest guides of that group by root (K = 4, Blender's default), weighted
///    as GuideLocator::fadedWeights() (the farthest of K + 1 faded to zero, so guides enter and
///    leave without popping).
/// 3. **Likeness** (GuideGrouping::Shape, the default): each weight is multiplied by
///    (1 − (u/τ)²)² (0 for u ≥ τ) and renormalized, u the likeness distance of the guide from the
///    nearest guide: the mean distance between their root-relative points at 16 equal fractions of
///    their lengths, over the longer length; τ = `likeness` (0.25). A parting or a layer between
///    two guides thus never averages them into a hair that belongs to neither (opposite sweeps
///    cancel into a spike; a short and a long guide into a hair of neither length); guides that
///    are alike blend as Blender's.
/// 4. **Points.** The new strand has round(Σ w_i n_i) vertices (n_i the guides' counts, at least
///    2); each guide is resampled by arc length to that count, taken as offsets from its root,
///    rotated from the guide root's frame to the new root's (FrameRule::Surface: the smallest
///    rotation taking the guide root's normal to the new root's, as Blender's "up" vectors;
///    World, the default: no rotation, because over a real scalp neighbouring guides already point
///    the right way and rotating long hair by the normals' difference fans and flares it), and the
///    weighted offsets are added to x̃.
///
/// The head is interpolateGuides()'s (GuideInterpolation.h), after either method.
#pragma once

#include <vdbhair/Parameters.h>
#include <vdbhair/helicoid/HelicoidInterpolation.h>
#include <vdbhair/strands/StrandSet.h>

#include <openvdb/util/NullInterrupter.h>

#include <cstdint>
#include <string>
#include <vector>

namespace vdbhair {

/// @brief Whether a new hair blends only guides shaped like its nearest one (see step 3).
enum class GuideGrouping
{
    None,   ///< every guide of the group by distance alone (Blender's node)
    Shape,  ///< guides unlike the nearest one fade out (the default)
};

/// @brief "none" or "shape".
const char* guideGroupingName(GuideGrouping grouping);
/// @throw ValueError naming @a name and the choices.
GuideGrouping guideGroupingFromName(const std::string& name);

/// @brief Which frame the guides' offsets are carried in from their roots to a new root (step 4).
enum class FrameRule
{
    World,    ///< offsets as they are (the default)
    Surface,  ///< turned by the smallest rotation between the guide root's normal and the new root's
};

struct PointInterpolationParams
{
    int neighbors = 4;  ///< K nearest guides (Blender's "Max Neighbors" default), K >= 1
    GuideGrouping grouping = GuideGrouping::Shape;
    /// τ of step 3: the likeness distance, a fraction of the longer guide's length, at which a
    /// guide no longer takes part. 0.25: a guide bent a quarter of its length away from the nearest
    /// one is another flow.
    double likeness = 0.25;
    std::size_t maxVertices = std::size_t(1) << 28;  ///< as HelicoidInterpolationParams
};

/// @brief The declared grouping and likeness (vdbhair/Parameters.h); the neighbours are
/// guideNeighborsParam()'s, shared with helicoid interpolation.
const ParamTable<PointInterpolationParams>& pointInterpolationParameters();

/// @brief The `neighbors` parameter of a verb that can blend guides either way (a struct @a P with
/// members `helicoid` and `points`: InterpolateParams, ReconstructParams): the K nearest guides
/// by root, for both methods; 0 leaves each method's own (PointInterpolationParams::neighbors for
/// points, every guide for helicoid).
template<typename P>
Param<P> guideNeighborsParam()
{
    // 0 stands for both methods' own defaults; any other value is both's (a negative one for the range check to refuse).
    ParamAccess<P, int> access{[](const P& p) {
                                   const bool own = p.helicoid.shepard.neighbors == ShepardParams{}.neighbors &&
                                                    p.points.neighbors == PointInterpolationParams{}.neighbors;
                                   return own ? 0 : p.points.neighbors;
                               },
                               [](P& p, int k) {
                                   p.helicoid.shepard.neighbors = k != 0 ? k : ShepardParams{}.neighbors;
                                   p.points.neighbors = k != 0 ? k : PointInterpolationParams{}.neighbors;
                               }};
    Param<P> n = makeParam<P>("neighbors", "Guides per new hair, nearest by root", "", access);
    n.min = 0;
    n.zeroMeans = "each method's own, " + std::to_string(PointInterpolationParams{}.neighbors) + " for points and every guide for helicoid";
    n.pythonNone = true;
    return n;
}

/// @brief What is known of the guides besides their points; each part optional.
struct GuideContext
{
    std::vector<Vec3d> normals;          ///< empty or #G unit normals at the guide roots (FrameRule::Surface)
    std::vector<std::int32_t> groups;    ///< empty or #G group ids
    FrameRule frames = FrameRule::World;
};

/// @brief What each new strand was blended from, as Unreal's groom importer takes it
/// (`groom_closest_guides`, `groom_guide_weights`: three per strand): the three guides of largest
/// weight (guide indices; ties to the lower index) and their weights over the three's sum. A
/// strand of fewer guides repeats its first guide with weight 0.
struct GuideBinding
{
    std::vector<std::int32_t> guides;  ///< 3 #R
    std::vector<float> weights;        ///< 3 #R
};

/// @brief New strands at every root by blending the points of @a guides (see above). In parallel,
/// identical for any thread count.
/// @param context with FrameRule::Surface, the roots need normals; with root normals and no guide
/// normals, each guide takes the normal of the root nearest it (as interpolateHelicoids()).
/// @throw ValueError (no guides, a guide of zero length or with non-finite points, no roots, bad
/// neighbors or likeness, normals or groups of the wrong size, a root group with no guide, surface
/// frames without normals), LimitError (estimated before any work), InterruptedError.
/// @param[out] groups optional: the number of distinct guide groups
/// @param[out] rootGroups optional: #R, the group each new hair blended (0 .. groups - 1, ids in
/// ascending order), so that later steps (clumps) keep groups apart too
/// @param[out] binding optional: the guides and weights of each new strand (see GuideBinding)
StrandSet interpolatePoints(const StrandSet& guides, const InterpolationRoots& roots, const PointInterpolationParams& params,
                            const GuideContext& context = {}, bool threaded = true,
                            openvdb::util::NullInterrupter* interrupter = nullptr, std::size_t* groups = nullptr,
                            std::vector<std::uint32_t>* rootGroups = nullptr, GuideBinding* binding = nullptr);

/// @brief The likeness distance u of two strands (step 3): the mean distance between their
/// root-relative points at 16 equal fractions of their lengths, over the longer length (0 for two
/// zero-length strands).
double likenessDistance(const Vec3f* a, std::size_t na, const Vec3f* b, std::size_t nb);

} // namespace vdbhair
