/// @file Synthesis.h
/// @brief Example-based hair synthesis (Wang et al. 2009, §3-5), end to end: a new hairstyle with
/// the wisp structure and detail of an example, on the example's scalp region.
///
/// Stages (each its own file; timed in SynthResult::stages):
/// 1. **scalp**: the scalp map (ScalpMap.h) on the sphere fitted to the example's roots, measured on
///    the scalp level set when one is given.
/// 2. **samples**: every strand resampled to n_s vertices in its root frame (StrandSamples.h).
/// 3. **clustering**: the example's hierarchy (Clustering.h), @c cluster.levels levels.
/// 4. **feature maps**: PCA (Pca.h) of the coarsest level to n_f components; the input map on a
///    (u, v) grid of spacing @c mapSpacing, valid within two root spacings of the example's roots
///    (FeatureMap.h); the output map by texture optimization (TextureOptimization.h) at the same
///    size (or the example's own, SynthLayout::Example).
/// 5. **coarsest level**: output roots scattered over the valid region (RootScatter.h) at the
///    example's density for that level (times @c strandScale); each root's strand rebuilt from the
///    output map's nearest feature vector.
/// 6. **detail transfer**, level by level to the finest (DetailTransfer.h), each level's roots
///    scattered at the example's density for the level.
/// 7. **refinement** after each level (§5.3, Refine.h with one level), the voxel size halving from
///    level to level down to the finest, which is Refine.h's own default for the example
///    (suggestVoxelSize(): three root spacings). The paper's 0.02 head radii at the coarsest level
///    makes a finest voxel of 0.005 radii, ten times finer than the roots of a 10,000-strand head:
///    each voxel then holds one strand, the field returns every strand as it is, and refining
///    straight.hair took 120 s instead of a few.
/// The output region is the example's (the valid pixels of its map) or one given as points.
/// Deterministic for a seed and independent of the thread count.
#pragma once

#include <vdbhair/Parameters.h>
#include <vdbhair/field/HeadObstacle.h>
#include <vdbhair/field/Refine.h>
#include <vdbhair/strands/StrandSet.h>
#include <vdbhair/synth/Clustering.h>
#include <vdbhair/synth/DetailTransfer.h>
#include <vdbhair/synth/FeatureImage.h>
#include <vdbhair/synth/FeatureMap.h>
#include <vdbhair/synth/Pca.h>
#include <vdbhair/synth/TextureOptimization.h>

#include <openvdb/util/NullInterrupter.h>

#include <chrono>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace vdbhair {

/// Where the coarsest level's feature map comes from.
enum class SynthLayout
{
    /// Texture optimization (Kwatra et al. 2005), the paper's §5.1: a new arrangement of the
    /// example's coarsest strands. The default.
    Synthesize,
    /// The example's own map: the output keeps the example's global flow exactly and gets new
    /// roots, new wisps and their transferred detail at every level (a variation of the example).
    Example
};
/// @throw ValueError unless "example" or "synthesize".
SynthLayout synthLayoutFromName(const std::string& name);
const char* synthLayoutName(SynthLayout layout);

struct SynthParams
{
    SynthLayout layout = SynthLayout::Synthesize;
    /// The strand's own edges (DetailTransfer.h says why): curls keep their turning per length
    DetailBlend detailBlend = DetailBlend::Edges;
    /// Each strand at its own length and pitch: the output's centres come from the example, of
    /// its lengths (transfer between hairstyles lays detail by arc length, HairTransfer.h).
    /// Measured on Curly_100 (--json, seeds 0-6): see the docs/synthesis.md.
    DetailScale detailScale = DetailScale::Strand;
    /// How output wisps choose the example's (balanced, DetailTransfer.h), near their own place
    DetailMatchParams match = [] {
        DetailMatchParams m;
        m.place = 1.0;
        return m;
    }();
    int vertices = StrandSamples::kDefaultVertices;  ///< n_s (Table 1)
    int components = Pca::kDefaultComponents;        ///< n_f (§5.1)
    ClusterParams cluster;                           ///< includes the level count and the seed
    /// Texture optimization, started from patches near their own place (TextureInit::Nearby), for
    /// the reason given at @c placeWeight. The example's invalid pixels (no hair) are filled with
    /// the nearest valid value first (Synthesis.cc): output windows at the region's edge otherwise
    /// match windows from inside it and average the edge's extremes away, the hair that hangs at
    /// the sides and back (measured on straight.hair: the output's hair stuck out sideways).
    TextureParams texture = [] {
        TextureParams t;
        t.init = TextureInit::Nearby;
        return t;
    }();
    /// Feature-map pixel spacing in (u, v) radians: 0.02 (Wang et al. §6's grid spacing for a head
    /// of radius 1; a radian of (u, v) is about a radius of arc near the crown).
    double mapSpacing = 0.02;
    /// Place guidance of the texture optimization: two extra channels hold each pixel's own (x, y),
    /// scaled so that a source @c texture.nearbyRadius away costs @c placeWeight times the features'
    /// RMS value. Features in root frames are not stationary over a scalp (hanging hair turns with
    /// the frame from the crown to the sides), so a source from far away rarely fits; measured on
    /// straight.hair, the output's median distance to the nearest example strand is 0.48 head radii
    /// unguided and 0.27 at weight 1 (0.28 at 4 and 16). 0 turns the guidance off (Kwatra's and the
    /// paper's stationary synthesis).
    double placeWeight = 1.0;
    double strandScale = 1.0;  ///< output strands per example strand, at every level
    /// Output strands at the finest level, coarser levels alike (0: the example's density over the
    /// output region, times @c strandScale)
    std::size_t strands = 0;
    /// With another scalp for the output: radians about its up axis that its layout is turned
    /// by against the example's (moveToScalp()), for heads that face different ways
    double outputTurn = 0.0;
    int rootIterations = 10;   ///< RootScatter.h relaxation rounds
    /// Output roots at the example's density, place by place (rootDensity() of each level's roots,
    /// RootScatter.h): a dense short crown stays dense. false: evenly over the region (the paper's
    /// "randomly generate hair roots" and Turk's relaxation)
    bool exampleDensity = true;
    /// The coarsest level's wisps in the feature map as offsets along the head's axes (a wisp read
    /// at a root higher or lower on the head hangs as it did); false: in each root's scalp frame,
    /// the paper's (a long wisp read at a higher root turned outward with the scalp's normal: Ruby's
    /// long hair flared, its tips 41 units out from the head against the example's 24, 90th
    /// percentile)
    bool mapInHeadAxes = true;
    bool refine = true;        ///< §5.3 after every level
    double voxelSize = 0.0;    ///< the finest level's refinement voxel, world units (0: suggestVoxelSize(example))
    RefineMode refineMode = RefineMode::Consistent;
    /// The scalp's up axis (the paper's +y, where u and v are least distorted); (0, 0, 0): the mean
    /// direction from the fitted sphere's centre to the roots, so the hair sits on the upper
    /// hemisphere of scalp space whatever the file's axes (cyHair files are z-up, USC's y-up).
    Vec3d up{0.0, 0.0, 0.0};
    /// The head's front, for the report by region (StyleRegions.h); (0, 0, 0): found from the
    /// example's hairline.
    Vec3d front{0.0, 0.0, 0.0};
    std::uint64_t seed = 0;
    /// Refuse outputs above this many vertices (16 bytes each with the samples, before refinement).
    std::uint64_t maxVertices = std::uint64_t(1) << 28;
    /// Also compare the output with its source as `vdbhair compare` does, for the report's
    /// "compare" (measureSynthesis(), measureTransfer(): 1-3 s more at 100,000 strands).
    bool measure = false;

    /// @throw ValueError naming the parameter, its value and the rule.
    /// The head the new hair may enter no deeper than the example's hair (keepHairOutOfHead()), swept out of it along a length as
    /// `interpolate`'s new hair is (HeadCollision.h). Unset: the scalp's level set when
    /// synthesizeHair() is given one, else the sphere fitted to the example's roots; with an
    /// output scalp and no head set, none (the caller knows the other head: the CLI passes its
    /// level set). HeadObstacle::none(): no head.
    HeadObstacle head;

    void validate(const char* where) const;
};

/// @brief synth's parameters declared once (Parameters.h): the hierarchy (levels, seed, vertices,
/// threshold, initial clusters), the coarsest level's layout (map spacing, layout, place weight,
/// nearby, root density) and detail transfer and refinement (components, detail, detail scale,
/// matching, refine mode, voxel size). `transfer` and `comb` declare theirs from these
/// (transferParameters(), combParameters()), with their own structs' defaults. Then what a run
/// takes besides: the output's strand count, refinement on or off, the axes (up, front: names on
/// the command line, names or vectors in Python, makeAxisParam()), the output turn and measuring.
/// The files (scalp, region, output scalp, head) are each front end's own.
const ParamTable<SynthParams>& synthParameters();

struct SynthStage
{
    std::string name;
    double seconds = 0.0;
};

struct SynthResult
{
    StrandSet strands;                    ///< the new hairstyle (the finest level), n_s vertices a strand
    /// element l-1 (l = 1 .. levels-1): for every output strand, its cluster at level l (the index of
    /// its ancestor among the output strands of level l)
    std::vector<std::vector<std::int32_t>> clusterOf;
    ClusterHierarchy example;             ///< the example's hierarchy
    std::vector<StrandSamples> output;    ///< the output's levels, 0 the finest
    Pca pca;                              ///< of the example's coarsest level
    UvGrid grid;
    FeatureImage inputMap, outputMap;
    TextureStats texture;
    std::vector<SynthStage> stages;
    std::shared_ptr<ScalpMap> map;
    std::vector<std::size_t> refinedCorrected;  ///< per output level (0 the finest): strands refinement corrected
    std::vector<double> refineVoxelSizes;       ///< per output level (0 the finest), world units
    Vec3d up{0.0, 1.0, 0.0};                    ///< the up axis used
    double outputArea = 0.0;                    ///< area of a given output region on the example's scalp (0: the example's region)
    std::string head;                           ///< the head used (HeadObstacle::describe()), "none" without one
    std::size_t headPushedOut = 0;              ///< output strands the head pushed out
    /// strands passing into the head (countStrandsEnteringHead(), headTolerance()): of the output, and of the example (0 on another head)
    std::size_t enteringHead = 0, exampleEnteringHead = 0;
};

/// Stage 1, the scalp map of a hairstyle (hairScalpMap(), scalpMapOfPoints()), is in field/ScalpMap.h.

/// @brief Stages 2-3: every strand sampled on @a map (in spatial order, Measures.h) and the
/// hierarchy of @a params.cluster with seed @a params.seed.
/// @param order if given, receives the spatial order: row i of level 0 is strand (*order)[i]
ClusterHierarchy hairHierarchy(const StrandSet& strands, const ScalpMap& map, const SynthParams& params, bool threaded = true,
                               openvdb::util::NullInterrupter* interrupter = nullptr,
                               std::vector<std::uint32_t>* order = nullptr);

/// @brief The roots of one output level: positions, and optionally each root's centre among the
/// coarser level's output strands (empty: the nearest coarser root, DetailTransfer.h step 1).
struct LevelRoots
{
    std::vector<Vec3d> positions;
    std::vector<std::uint32_t> parent;
};

/// @brief Stages 6-7 onto any coarsest level: from @a res.output[L-1] (set by the caller) level by
/// level to the finest, each level's strands rooted at @a rootsOf(l), their detail transferred from
/// @a source (DetailTransfer.h), and refined (§5.3) as @a params say, at voxel @a finestVoxel
/// doubled per coarser level. The coarsest level itself is refined only if @a refineCoarsest.
/// Fills res.output, res.strands, res.clusterOf, res.refinedCorrected, res.refineVoxelSizes and
/// res.stages. Shared by synthesis, imposed coarsest levels and transfer (HairTransfer.h).
/// @param outputVertices vertices per strand of the finer output levels (0: n_s); transfer onto
/// longer hair gives them more, so that detail laid by arc length is not undersampled
void synthesizeFinerLevels(SynthResult& res, const ClusterHierarchy& source,
                           const std::function<LevelRoots(int level)>& rootsOf, const SynthParams& params,
                           double finestVoxel, bool refineCoarsest, openvdb::FloatGrid::ConstPtr scalp, bool threaded,
                           openvdb::util::NullInterrupter* interrupter, int outputVertices = 0);

/// @brief Adds the seconds from its construction to its destruction to the stage named @a name of
/// @a stages (appended when new).
struct SynthStageTimer
{
    std::vector<SynthStage>& stages;
    std::string name;
    std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now();
    ~SynthStageTimer();
};

/// @brief Synthesize a hairstyle from @a example.
/// @param scalp the scalp level set (`surface`), or null for the sphere fitted to the roots
/// @param outputRegion where the new hair grows, as world points on or near the scalp (the roots
/// of another hairstyle, follicles, a region grid's voxels): the (u, v) pixels within two of their
/// median spacings (at least a map pixel) of one of them; null: the example's own region. The
/// map covers both regions; the example's features are extended into pixels it lacks by the
/// nearest (Synthesis.cc), and the strand count of every level scales with the ratio of the
/// regions' areas (in scalp space).
/// @param outputScalp another head for the output (scalpMapOfPoints() of its region): the
/// region's points are on it, the hairstyle is synthesized on the example's scalp at their (u, v)
/// and moved onto it at the end (moveToScalp()); the output's refinement is the example's scalp's.
/// @throw ValueError (bad parameters, too few strands, strands of fewer than 2 vertices, an empty
/// region), LimitError (an output beyond maxVertices), InterruptedError.
SynthResult synthesizeHair(const StrandSet& example, const SynthParams& params,
                           openvdb::FloatGrid::ConstPtr scalp = nullptr, bool threaded = true,
                           openvdb::util::NullInterrupter* interrupter = nullptr,
                           const std::vector<Vec3d>* outputRegion = nullptr, std::shared_ptr<const ScalpMap> outputScalp = nullptr);

/// @brief The head a synthesis keeps its new hair out of (SynthParams::head): the one set; else
/// none when the hair grows on @a otherHead (the caller sets that head); else @a scalp's level
/// set; else the sphere fitted to @a roots' roots (headFromRoots()).
HeadObstacle synthesisHead(const SynthParams& params, openvdb::FloatGrid::ConstPtr scalp, bool otherHead, const StrandSet& roots, const Vec3d& up);

/// @brief The last step of synthesizeHair() and transferHairstyle(): @a res.strands swept out of
/// @a head along a length (HeadCollision.h) with HeadDepthRule::Rising, no vertex deeper than the
/// @a reference strand (the example or the base) with the nearest root at the same arc length
/// (referenceDepthAllowance(); roots deeper than that strand's lifted to its depth first,
/// liftRootsToReference()), or than its own root when @a reference is null; and the strands
/// passing into it counted, of the output and of @a reference. Sets SynthResult::head,
/// headPushedOut, enteringHead, exampleEnteringHead.
void keepHairOutOfHead(SynthResult& res, const HeadObstacle& head, const StrandSet* reference, bool threaded = true);

} // namespace vdbhair
