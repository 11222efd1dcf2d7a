/// @file GuideInterpolation.h
/// @brief The `interpolate` operation: new hairs at roots from guide hairs, by either method, with
/// the head as an obstacle (no new vertex deeper inside it than its strand's root, pushed out
/// smoothly: HeadCollision.h) and a report of what came out. The command line and Python both call
/// interpolateGuides(); the methods themselves are PointInterpolation.h (the default) and
/// HelicoidInterpolation.h (Piuze et al. 2011, §4).
///
/// Why points is the default: measured on real grooms with their own heads (docs/interpolation.md),
/// blending the guides' points by group and likeness keeps new hair inside the guides' hair volume
/// about as well as the groom itself; blending helicoid parameters fans and flares it (fits of
/// neighbouring real strands are not parameterized alike), and rotating guides by their roots'
/// surface normals flares long hair. Helicoid interpolation stays available (`--method helicoid`),
/// as the paper prints it.
#pragma once

#include <vdbhair/field/HeadObstacle.h>
#include <vdbhair/helicoid/GroomControls.h>
#include <vdbhair/helicoid/HelicoidInterpolation.h>
#include <vdbhair/helicoid/PointInterpolation.h>
#include <vdbhair/helicoid/Scene.h>
#include <vdbhair/strands/StrandSet.h>

#include <openvdb/util/NullInterrupter.h>

#include <cstdint>
#include <string>
#include <vector>

namespace vdbhair {

enum class InterpolationMethod
{
    Points,    ///< the guides' own points, by group and likeness (PointInterpolation.h): the default
    Helicoid,  ///< the guides' p-helicoid parameters (HelicoidInterpolation.h, Piuze et al. §4)
};

/// @brief "points" or "helicoid".
const char* interpolationMethodName(InterpolationMethod method);
/// @throw ValueError naming @a name and the choices.
InterpolationMethod interpolationMethodFromName(const std::string& name);
/// @brief "world" or "surface".
const char* frameRuleName(FrameRule frames);
/// @throw ValueError naming @a name and the choices.
FrameRule frameRuleFromName(const std::string& name);

struct InterpolateParams
{
    InterpolationMethod method = InterpolationMethod::Points;
    FrameRule frames = FrameRule::World;  ///< Surface needs root normals (§4.3)
    HelicoidInterpolationParams helicoid;
    PointInterpolationParams points;
    /// Curl, clumps and frizz on the new hair (its seed is `seed`); density and length come with the roots
    GroomParams groom;
    std::uint64_t seed = 0;    ///< the density draw, the groom controls, waviness noise of the new helicoid hairs
    bool returnScene = false;  ///< Helicoid: keep the new hairs as a scene, not grown (no head collision, no groom controls then)
};

/// @brief interpolate's declared parameters (vdbhair/Parameters.h): the method, the points' and
/// helicoids' (pointInterpolationParameters(), helicoidInterpolationParameters(),
/// guideNeighborsParam()), the groom controls (groomParameters()), frames, seed and vertex cap.
/// The up axis, the roots, their density and length, the head and returnScene are the front ends'.
const ParamTable<InterpolateParams>& interpolateParameters();

/// @brief Whether @a groom asks for a control that moves hair: clumps, curl or frizz (a positive
/// clump radius, curl amplitude or frizz). interpolateGuides() applies them only then, and refuses
/// them with InterpolateParams::returnScene (a scene of new hairs is not grown, so nothing to move).
bool groomsHair(const GroomParams& groom);

/// @brief The guides: strands (blended as they are by points; fitted first for helicoids) or a
/// helicoid scene (grown without wisps for points). Exactly one of the two.
struct InterpolationGuides
{
    const StrandSet* strands = nullptr;
    const Scene* scene = nullptr;
    std::vector<std::int32_t> groups;  ///< empty or #G group ids (points only)
    std::string where = "guides";      ///< names the guides in messages (a path)
};

/// The most new strands the volume measure looks at (InterpolateResult::leavingVolume): a share
/// measured on 100,000 strands spread evenly over the output is within half a point of the whole's.
constexpr std::size_t kVolumeSample = 100000;

struct InterpolateResult
{
    StrandSet strands;  ///< the new hairs (empty with returnScene)
    Scene scene;        ///< Helicoid: the new hairs as helicoids
    std::size_t guides = 0, groups = 1;
    std::size_t roots = 0;          ///< roots given
    std::size_t rootsDropped = 0;   ///< of them, left bare by density or a length of 0
    std::size_t cut = 0;            ///< new hairs cut to a length under 1
    GroomStats groom;               ///< curl, clumps, frizz
    /// Points: each new strand's three guides of largest weight (indices into the guides) and
    /// their weights (GuideBinding), for Unreal's groom attributes; empty for Helicoid.
    GuideBinding binding;
    std::size_t pushedOut = 0;         ///< new strands the head pushed out (swept, before curl, clumps and frizz)
    std::size_t groomPushedOut = 0;    ///< strands with vertices that curl, clumps or frizz moved into the head, pushed back out one by one
    std::size_t verticesTooDeep = 0;   ///< vertices the push could not bring out (HeadCollision.h)
    /// strands that pass into the head (countStrandsEnteringHead(), headTolerance()): of the new hair, and of the guides
    std::size_t enteringHead = 0, guidesEnteringHead = 0;
    /// of `volumeSample` new strands (every one, or evenly spread kVolumeSample of them), those that
    /// leave the guides' hair volume (countStrandsLeavingVolume(), field/HairVolume.h) at the guides'
    /// suggested voxel size `volumeVoxel` (suggestVoxelSize())
    std::size_t leavingVolume = 0, volumeSample = 0;
    double volumeVoxel = 0.0;
    double fitSeconds = 0.0;  ///< fitting strand guides (Helicoid)
    double seconds = 0.0;     ///< interpolating (and growing, and the head)
};

/// @brief New hairs at @a roots from @a guides (see above), then the groom controls in
/// GroomControls.h's order and the head. Identical for any thread count.
/// @param head the head to keep the new hair out of (empty: none)
/// @throw ValueError (bad guides, roots, groups or params, groups with Helicoid, surface frames
/// without normals), LimitError (too many vertices, before any work), InterruptedError.
InterpolateResult interpolateGuides(const InterpolationGuides& guides, const InterpolationRoots& roots, const HeadObstacle& head,
                                    const InterpolateParams& params, bool threaded = true,
                                    openvdb::util::NullInterrupter* interrupter = nullptr);

/// @brief Write the groom of an interpolation as Unreal's groom importer takes it (AbcFile.h): the
/// guides as the Curves object `guides` (groom_guide 1, groom_id 0 .. G-1, their groom_group_id
/// when @a guideGroups is given) and the new hair as `hair` (groom_guide 0, groom_id G .. G+S-1,
/// and per strand the groom_closest_guides and groom_guide_weights of @a result's binding, and
/// the group of its first guide). Reading the file back gives the new hair (the guides are left
/// out with a warning).
/// @param guides the guide strands @a result was made from (a scene's: growGuides())
/// @throw ValueError when @a result has no binding (Helicoid) or sizes disagree; IoError.
void writeGroomAbc(const std::string& path, const StrandSet& guides, const std::vector<std::int32_t>& guideGroups,
                   const InterpolateResult& result);

} // namespace vdbhair
