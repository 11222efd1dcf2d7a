/// @file Prepare.h
/// @brief A hairstyle made ready for a dataset in one call, `vdbhair prepare`: evenly spread
/// strands kept (RootSubsample.h), the groom moved onto a common head (SimilarityAlign.h), every
/// strand resampled to one vertex count (strands/Resample.h), and strands pushed out of the head
/// (field/HeadCollision.h), with a report of what each step did (toJson(): the CLI's --json, the
/// batch manifest's columns and Python's dict alike).
///
/// The order: subsample (even roots are unchanged by a similarity, and later steps then touch
/// fewer strands), align, resample, fix penetration. Penetration is fixed last because a
/// resampled strand's chords cut inside a convex head where the strand wraps around it; the fix
/// keeps every segment's length, so the vertex count and the equal spacing survive it.
#pragma once

#include <vdbhair/Parameters.h>
#include <vdbhair/dataset/RootSubsample.h>
#include <vdbhair/dataset/SimilarityAlign.h>
#include <vdbhair/field/HeadCollision.h>
#include <vdbhair/io/MeshFile.h>
#include <vdbhair/strands/StrandSet.h>

#include <nlohmann/json.hpp>

#include <cstddef>
#include <optional>

namespace vdbhair {

/// What --fix-penetration does with a root inside the head.
enum class RootDepth
{
    Keep,    ///< the root stays; its strand may be as deep as the root, no deeper (interpolate's rule)
    Surface  ///< the strand is first moved along the head's normal at its root until the root is on the surface
};

/// @throw ValueError unless "keep" or "surface".
RootDepth rootDepthFromName(const std::string& name);
const char* rootDepthName(RootDepth depth);

struct PrepareParams
{
    std::size_t points = 0;   ///< vertices per strand after resampling (at least 2); 0 keeps them
    std::size_t strands = 0;  ///< strands kept (even roots); 0 keeps all
    /// Aligning by ICP, the groom's head is first cut to its vertices within this many times the
    /// roots' radius (their largest distance from their centroid) of the roots' centroid: the
    /// head the hair grows on, without the bust or shoulders many groom meshes carry (TressFX's
    /// Ruby: a bust 290 units wide), whose vertices would otherwise outweigh the head's and fit it
    /// to the common head at half its size. 2 was chosen on the shared grooms by looking at the
    /// results (docs/datasets.md): at 1.5 straight.hair's head is fitted rolled 27 degrees (its
    /// straight strands hang aslant), at 2.5 and more, or 0, Ruby's head at half size. 0 keeps
    /// every vertex.
    double headCrop = 2.0;
    /// The common head's up axis (vdbhair's convention, and USC-HairSalon's: +Y). The groom's up is
    /// the direction from its whole head's centroid to its roots' centroid; ICP starts only
    /// from rotations that keep the two within 90 degrees (AlignParams::sourceUp). Zero: any start.
    Vec3d targetUp{0.0, 1.0, 0.0};
    AlignParams align;
    HeadCollisionParams collision;
    /// Keep suits hair whose roots sit on the head; after aligning to another person's head,
    /// roots can end under the new scalp and Surface brings them (and their strands) up to it.
    RootDepth rootDepth = RootDepth::Keep;

    /// @throw ValueError naming the field, the value and the rule.
    void validate() const;
};

/// @brief prepare's parameters declared once (vdbhair/Parameters.h): the command's options and
/// `--help`, Python's prepare() keywords and docs/cli.md's table are made from it. The target's
/// up axis stays the front ends' own (an axis name on the command line).
const ParamTable<PrepareParams>& prepareParameters();

struct PrepareReport
{
    std::size_t inputStrands = 0, inputVertices = 0;
    std::size_t strands = 0, vertices = 0;  ///< after every step
    std::optional<RootSelection> subsample;  ///< when params.strands was given (strand list left empty)
    std::size_t requestedStrands = 0;
    std::optional<AlignResult> align;         ///< when a target head was given
    std::size_t headVertices = 0;             ///< the groom's head vertices the alignment used (after headCrop)
    std::size_t points = 0;                   ///< params.points (0: kept)
    /// Fixing penetration (when a head was given): strands entering the head (countStrandsEnteringHead()
    /// at headTolerance()) before and after, and resolveHeadCollisions()' figures.
    bool fixed = false;
    std::size_t enteringBefore = 0, enteringAfter = 0;
    HeadCollisionStats collision;
    std::size_t rootsLifted = 0;  ///< strands moved up to the surface (RootDepth::Surface)
    double tolerance = 0.0;
    std::string fixHead;  ///< the head's description (HeadObstacle::describe())
};

/// @brief Prepare @a strands in place (see above).
/// @param head the groom's own head (the source of the alignment); needed when @a alignTo is given
/// @param alignTo the common head to move the groom onto, or null for no alignment
/// @param fixHead the head to push strands out of (in the output's frame: the common head when
/// aligning), or null; strands rooted inside its scalp may stay as deep as their root
/// (rootDepthAllowance(), the rule new hair gets in `interpolate`), no deeper
/// @throw ValueError for bad params, an alignment without @a head, or what alignMeshes() throws.
PrepareReport prepareStrands(StrandSet& strands, const PrepareParams& params, const TriangleMesh* head,
                             const TriangleMesh* alignTo, const HeadObstacle* fixHead, bool threaded = true);

/// @brief The vertices of @a mesh within @a factor times the roots' radius of the roots' centroid,
/// and the triangles between them. See PrepareParams::headCrop.
TriangleMesh cropMeshToRoots(const TriangleMesh& mesh, const StrandSet& strands, double factor);

/// @brief Every strand whose root is inside @a head moved, whole, along the head's normal until its
/// root is on the surface (HeadObstacle::Probe::pushOut()). In parallel. @return how many moved.
std::size_t liftRootsToSurface(StrandSet& strands, const HeadObstacle& head, bool threaded = true);

/// @brief @a s moved by @a t: positions, and thickness (per vertex and default) scaled.
void transformStrands(StrandSet& s, const Similarity& t);

/// @brief The report as JSON (`prepare --json`, Python's vdbhair.prepare()).
nlohmann::json toJson(const PrepareReport& r);
/// @brief A similarity as JSON: scale, rotation (3 rows), translation, and the 4x4 matrix (rows).
nlohmann::json toJson(const Similarity& t);

} // namespace vdbhair
