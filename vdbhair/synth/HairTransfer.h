/// @file HairTransfer.h
/// @brief Detail transfer between hairstyles and imposed coarsest levels (Wang et al. 2009, §6:
/// "retaining the original coarsest level of the second hairstyle and transferring finer-level
/// details from the first one"; "directly impose an arbitrary coarsest level").
///
/// 1. Both hairstyles get their scalp map (Synthesis.h, stage 1): DETAILS on the sphere fitted to
///    its roots, BASE on its own (measured on BASE's scalp level set when one is given). The output
///    lives on BASE's scalp.
/// 2. DETAILS' hierarchy (Clustering.h). Its samples are in units of its own head radius, so its
///    detail arrives scaled to BASE's head (a curl of a tenth of a head radius stays one); its
///    roots are scaled by BASE's radius over DETAILS' for the root offsets to match.
/// 3. DETAILS' coarsest strands are smoothed (the paper: "to ensure a thorough high-frequency
///    detail transfer, we further smooth the geometry of the individual hair strands at the
///    coarsest level of the first hairstyle"): a Gaussian (Resample.h's smoothPolyline(), both
///    ends kept) at one scale in head radii for both hairstyles, σ = @c smoothing of BASE's median
///    coarsest wisp length: @c smoothing × the length ratio (at most 1) of DETAILS' vertices, and
///    @c smoothing of BASE's (TransferResult::detailsSmoothing). Short curly DETAILS onto long
///    BASE wisps so gives up its whole-strand bends as detail too, which BASE's flow would otherwise
///    replace (Curly_100 keeps 63 % of its turning under a smoothing of 1/8 of its own length). What the smoothing removes from a
///    coarsest strand moves into the detail of the level below, so a curly DETAILS gives its curl
///    to a straight BASE instead of keeping it in the coarse flow that BASE replaces.
/// 4. The coarsest output level is BASE's: the coarsest level of BASE's own hierarchy, or with
///    @c guides BASE's strands as they are (a few guide hairs, a grown scene).
/// 5. Finer levels by cluster-oriented detail transfer and refinement (Synthesis.h,
///    synthesizeFinerLevels(); the coarsest level is not refined, so it stays BASE's exactly). Each
///    level's roots are BASE's: the roots of its hierarchy's level, and at the finest BASE's own
///    strands' roots in BASE's order (the output has BASE's strands, outputVertices each). With
///    @c guides, roots are scattered over the guides' region (RootScatter.h) at DETAILS' ratio of
///    strands per coarsest strand (or @c strands at the finest).
///
/// Lengths: Eq. 5-8 compare strands vertex by vertex, so when a BASE wisp is k times as long as
/// the DETAILS wisp matched to it, its curls come out k times as long and k times fewer (the
/// paper's stated limitation, DetailScale::Index). By default detail is laid by arc length
/// instead (DetailScale::ArcLength): curls keep their size and spacing, repeated (mirrored) along
/// a longer strand; the finer output levels then get n_s × length ratio vertices per strand (rounded;
/// at most kMaxOutputVertices and within @c outputVertexBudget), so that a BASE strand k times as long as DETAILS' carries the curls at
/// DETAILS' own sample spacing instead of undersampling them (Curly_100's curls onto straight.hair
/// at 64 vertices kept 4.4 of their 7.9 turning per head radius; TransferResult::outputVertices
/// says what was used). The transfer refuses hairstyles whose coarsest wisps differ in median length
/// by more than @c maxLengthRatio, where clusters cannot be matched in any useful sense, and
/// reports the ratio otherwise.
#pragma once

#include <vdbhair/synth/Synthesis.h>

namespace vdbhair {

/// The most vertices per output strand that laying detail by arc length asks for.
constexpr int kMaxOutputVertices = 1024;

struct TransferParams
{
    /// vertices, components, cluster (levels, ε), detail blend, refinement, up, seed, caps; detail
    /// laid by arc length (DetailTransfer.h), since the two hairstyles' lengths differ
    SynthParams synth = [] {
        SynthParams p;
        p.detailScale = DetailScale::ArcLength;
        // DETAILS' wisps differ from BASE's in length and shape more than an example's from its
        // synthesis: balanced matching looks further for a wisp with share left.
        p.match.candidates = 64;
        p.match.place = 0.0;  // two hairstyles' places are not one another's
        return p;
    }();
    /// σ of the smoothing of the coarsest strands, as a fraction of BASE's vertices (DETAILS': of
    /// BASE's wisp length, above; StrandSamples::kDetailSmoothing says why); 0 smooths nothing.
    double smoothing = StrandSamples::kDetailSmoothing;
    bool smoothBase = true;      ///< smooth BASE's coarsest level alike (false: the paper's rule)
    bool guides = false;         ///< BASE's strands are the coarsest level as they are
    std::size_t strands = 0;     ///< with @c guides: output strands (0: DETAILS' strands per coarsest strand × guides)
    /// Refuse coarsest wisps whose median lengths (head radii) differ more: the matching compares
    /// whole centres, and beyond this a match says little (Curly_100's wisps onto straight.hair's
    /// are 9.3 times apart and still transfer their curls by arc length).
    double maxLengthRatio = 16.0;
    /// Laying detail by arc length raises the output's vertices per strand (above) only while the
    /// output stays within this many vertices (10,000 strands of 400; a 50,000-strand head gets 80).
    std::uint64_t outputVertexBudget = 4'000'000;

    /// @throw ValueError naming the parameter, its value and the rule.
    void validate(const char* where) const;
};

/// @brief transfer's parameters declared once (Parameters.h): synth's hierarchy, detail transfer
/// and refinement (synthParameters(), nested: their defaults are TransferParams::synth's), then
/// the smoothing, the guides, the output's strand count with guides and BASE's smoothing switch;
/// refinement on or off, up, front and measuring are synth's (measured against BASE). The files
/// (scalp, head) are each front end's own.
const ParamTable<TransferParams>& transferParameters();

struct TransferResult
{
    /// The output: strands, levels (output.back() is BASE's coarsest level), clusterOf, stages;
    /// @c example is DETAILS' hierarchy (roots in BASE's scale, coarsest level smoothed) and @c map BASE's.
    SynthResult result;
    ClusterHierarchy base;          ///< BASE's hierarchy (empty with @c guides)
    /// #BASE's strands: each one's coarsest cluster, the output's coarsest strand it became (with
    /// @c guides, its own index); with result.clusterOf.back() it pairs BASE's wisps with the output's
    std::vector<std::int32_t> baseLabel;
    std::shared_ptr<ScalpMap> detailsMap;
    double detailScale = 1.0;       ///< BASE's head radius over DETAILS'
    double lengthRatio = 1.0;       ///< median coarsest-wisp length of BASE over DETAILS', in head radii
    int outputVertices = 0;         ///< vertices per strand of the finer output levels (n_s, or more: above)
    double detailsSmoothing = 0.0;  ///< σ of DETAILS' coarsest smoothing, a fraction of its vertices (above)
};

/// @brief Transfer @a details' finer levels onto @a base's coarsest level.
/// @param baseScalp BASE's scalp level set (`surface`), or null for the sphere fitted to its roots
/// @throw ValueError (bad parameters; too few strands for the levels, naming which hairstyle;
/// wisps too different in length to match), LimitError (outputs beyond maxVertices), InterruptedError.
TransferResult transferHairstyle(const StrandSet& details, const StrandSet& base, const TransferParams& params,
                                 openvdb::FloatGrid::ConstPtr baseScalp = nullptr, bool threaded = true,
                                 openvdb::util::NullInterrupter* interrupter = nullptr);

/// @brief Smooth every row of @a samples (StrandSamples.h) with σ = @a fraction × its vertices,
/// root and tip kept (smoothPolyline()); lengths are updated.
void smoothSamples(StrandSamples& samples, double fraction, double radius);

} // namespace vdbhair
