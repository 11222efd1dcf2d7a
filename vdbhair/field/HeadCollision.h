/// @file HeadCollision.h
/// @brief Generated strands pushed out of the head smoothly, over a length of the strand, not
/// bent at one vertex: what `interpolate` (and any verb that makes new hair) does with the head.
///
/// Each strand may reach into the head only as deep as it is allowed at each vertex (an allowance
/// per vertex, world units: 0 keeps it outside; rootDepthAllowance(), what new hair gets, lets a
/// strand rooted inside the scalp stay as deep as its root and no deeper; HeadDepthRule::Rising
/// also keeps each vertex no deeper than the vertices before it, so new hair rises out of the
/// scalp it grows from and does not dive back in). The root never moves.
///
/// A sweep goes from root to tip, each segment keeping its direction and length from the (already
/// placed) vertex before it, so below a contact the strand keeps its shape, moved out; where a
/// vertex is deeper than allowed, its segment turns towards the head's outward normal by the least
/// angle that brings it to its floor. Lengths are kept exactly and nothing folds. That turn is made
/// at one vertex; to spread it, each edge's turn from the strand as given (a rotation vector) is
/// smoothed along the strand by a Gaussian in arc length (σ = `spread` × the strand's length; on a
/// finely sampled strand, edges past the tip turn as its last, so that a contact there spreads back), the
/// strand is rebuilt from its root with its own edges turned by the smoothed rotations, and it is
/// swept again from there: the edges before a contact now start to lift it, so the next sweep
/// meets the head at a shallower angle and turns less. Passes repeat while a sweep turns an edge
/// by more than 5 degrees (up to `passes`); of the swept strands, the one with the smallest
/// largest turn between two edges is kept (a strand along the surface may not settle, each sweep
/// turning as much as the smoothing took back); where that one still turns more than 45 degrees at
/// a vertex and the strand as given did not, passes that rebuild the strand each sweep was given
/// (accumulating the smoothed turns) run as well, and the less kinked is kept. Where no turn in
/// the sweep's plane lifts a vertex (a thin part of the level set, whose normals an edge apart
/// point opposite ways), the least turn towards any direction that does is taken; under
/// HeadDepthRule::Allowance an edge that would bend more than 45 degrees from the edge before
/// turns from that edge's direction instead, if that bends it less (a strand pressed head-on
/// slides on along the surface). The strand's own shape (curls,
/// waves) rides along: its edges are turned, not its positions smoothed (which would straighten
/// it and, on a convex head, pull it back in), and a smooth rotation field cannot fold it the way
/// smoothed displacements can (a strand pressed head-on into the head). A last pass pushes what is
/// left along the normal vertex by vertex, so no vertex ends deeper than allowed except where
/// HeadObstacle::Probe::pushOut() cannot reach: counted, not hidden.
#pragma once

#include <vdbhair/field/HeadObstacle.h>
#include <vdbhair/strands/StrandSet.h>

#include <cstddef>
#include <cstdint>
#include <vector>

namespace vdbhair {

/// A turn between two consecutive edges above this many degrees is a kink: what the sweep avoids
/// making (below) and what `comb` reports as a new kink (CombStats::newKinks).
constexpr double kKinkDegrees = 45.0;

/// How deep a vertex may be: as its allowance says, or also no deeper than its strand was before it.
enum class HeadDepthRule
{
    Allowance,  ///< each vertex as deep as its allowance (the input's own depth, for edits such as comb)
    Rising      ///< and no deeper than the shallowest vertex before it (new hair: out of the scalp, never back in)
};

struct HeadCollisionParams
{
    /// The reach of the smoothing that spreads a turn, a fraction of the strand's length (the
    /// Gaussian's σ in arc length). A tenth, with 12 passes, brings the 16-vertex strands of Ruby's
    /// long hair and of straight.hair pressed into their heads out with new turns over 45 degrees
    /// between two edges on 0.2 % and 0.1 % of them (0.5 % and 0.2 % after 8 passes; 1.5 % and
    /// 19.6 % with the Laplacian relaxation of positions used before); a fifth moves more of each
    /// strand than the contact needs.
    double spread = 0.1;
    int passes = 12;  ///< sweep-and-smooth passes before the vertex-by-vertex one
    HeadDepthRule depthRule = HeadDepthRule::Allowance;
};

struct HeadCollisionStats
{
    std::size_t strandsMoved = 0;     ///< strands with at least one vertex moved
    std::size_t verticesTooDeep = 0;  ///< vertices still deeper than allowed after every pass
};

/// @brief Push the strands of @a strands out of @a head (see above), in place. In parallel,
/// identical for any thread count. Nothing happens when @a head is empty.
/// @param allowedDepth empty (0 everywhere: outside), or #V non-negative depths in world units
/// @throw ValueError for an allowance of the wrong size or a negative or non-finite value, or bad params.
HeadCollisionStats resolveHeadCollisions(StrandSet& strands, const HeadObstacle& head, const std::vector<float>& allowedDepth,
                                         const HeadCollisionParams& params = {}, bool threaded = true);

/// @brief For each vertex of @a strands, how deep inside @a head its strand's root is (0 for a root
/// outside): the allowance that keeps new hair from going deeper than where it grows.
std::vector<float> rootDepthAllowance(const StrandSet& strands, const HeadObstacle& head, bool threaded = true);

/// @brief For each vertex of @a strands, how deep inside @a head the strand of @a reference whose
/// root is nearest its root is at the same arc length from the root (linear between its vertices,
/// its tip's depth beyond its length; 0 where it is outside): the allowance that keeps new hair no
/// deeper in the head than the hair it was made from, by refine --head's rule (HeadPolicy::NoDeeper:
/// the input's vertex at the same arc length), with the example or the base as the input. The
/// allowance falls by at most tan 30° per unit of arc length from the strand's own root depth on
/// (where the reference leaves the head within a segment, or the new root is deeper than the
/// reference's), so that its floor rises over a length instead of at one vertex.
/// @param nearest each strand's nearest @a reference strand (liftRootsToReference()'s), or null to search
/// @throw ValueError if @a reference has no strands, or @a nearest is not one index a strand.
std::vector<float> referenceDepthAllowance(const StrandSet& strands, const StrandSet& reference, const HeadObstacle& head, bool threaded = true,
                                           const std::vector<std::uint32_t>* nearest = nullptr);

/// @brief Let the allowance @a allowed of one strand (its @a n vertices at @a positions) fall by at
/// most tan 30° per unit of arc length from vertex to vertex, raising it where it falls faster: a
/// floor that jumps (where the hair it follows leaves the head within a segment) would turn the
/// strand at one vertex; so it rises over a length.
void limitAllowanceFall(const Vec3f* positions, std::size_t n, float* allowed);

/// @brief New hair grows where the reference's does: each strand of @a strands whose root is deeper
/// inside @a head than the root of the @a reference strand nearest it is moved out, whole (its
/// shape unchanged), along the head's normal at its root by the difference. In parallel, identical
/// for any thread count. @return how many strands moved.
/// @param nearest if given, receives each strand's nearest @a reference strand (#S indices), for
/// referenceDepthAllowance() to reuse
/// @throw ValueError if @a reference has no strands.
std::size_t liftRootsToReference(StrandSet& strands, const StrandSet& reference, const HeadObstacle& head, bool threaded = true,
                                 std::vector<std::uint32_t>* nearest = nullptr);

/// @brief How many strands of @a strands pass into @a head: have a vertex after the root more than
/// @a tolerance (world units) inside it and deeper than their root by as much. 0 for an empty head.
/// @param tolerance what counts as touching, not entering: headTolerance() for a head read from a
/// mesh, whose level set is exact only to a fraction of its voxel
std::size_t countStrandsEnteringHead(const StrandSet& strands, const HeadObstacle& head, double tolerance, bool threaded = true);

/// @brief Half the voxel of a level-set head (hair lying on a scalp is within that of it), 0 for a
/// sphere or no head.
double headTolerance(const HeadObstacle& head);

} // namespace vdbhair
