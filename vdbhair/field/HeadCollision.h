/// @file HeadCollision.h
/// @brief Generated strands pushed out of the head smoothly, over a length of the strand, not
/// bent at one vertex: what `interpolate` (and any verb that makes new hair) does with the head.
///
/// Each strand may reach into the head only as deep as it is allowed at each vertex (an allowance
/// per vertex, world units: 0 keeps it outside; rootDepthAllowance(), what new hair gets, lets a
/// strand rooted inside the scalp stay as deep as its root and no deeper). The
/// root never moves. A sweep goes from root to tip, each segment keeping its direction and length
/// from the (already placed) vertex before it, so below a contact the strand keeps its shape,
/// moved out; where a vertex is deeper than allowed, its segment turns towards the head's outward
/// normal by the least angle that brings it to its floor. Lengths are kept exactly and nothing
/// folds: a strand that runs into the scalp follows it until its own direction leads away (a
/// straight strand aimed into a sphere wraps around it, turning as the sphere does). The stretch within
/// `spread` × the strand's length of a turn is then relaxed by Laplacian steps (segment lengths
/// restored from the root after each), so the bend is spread over a length instead of made at one
/// vertex, and swept again; passes repeat while anything turns (up to `passes`, ending on a
/// sweep). A last pass pushes what is left along the normal vertex by vertex, so no vertex ends
/// deeper than allowed except where HeadObstacle::Probe::pushOut() cannot reach (beyond a level
/// set's band): counted, not hidden.
#pragma once

#include <vdbhair/field/HeadObstacle.h>
#include <vdbhair/strands/StrandSet.h>

#include <cstddef>
#include <vector>

namespace vdbhair {

struct HeadCollisionParams
{
    /// How far along the strand from a pushed vertex the bend is relaxed, a fraction of the
    /// strand's length: wide enough that a strand lifts off the scalp over a stretch.
    double spread = 0.15;
    int passes = 4;     ///< sweep-and-relax passes before the vertex-by-vertex one
    int smoothing = 4;  ///< Laplacian steps of each pass
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

/// @brief How many strands of @a strands pass into @a head: have a vertex after the root more than
/// @a tolerance (world units) inside it and deeper than their root by as much. 0 for an empty head.
/// @param tolerance what counts as touching, not entering: headTolerance() for a head read from a
/// mesh, whose level set is exact only to a fraction of its voxel
std::size_t countStrandsEnteringHead(const StrandSet& strands, const HeadObstacle& head, double tolerance, bool threaded = true);

/// @brief Half the voxel of a level-set head (hair lying on a scalp is within that of it), 0 for a
/// sphere or no head.
double headTolerance(const HeadObstacle& head);

} // namespace vdbhair
