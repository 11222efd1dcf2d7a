/// @file TangentField.h
/// @brief Strands to a sparse tangent field: the robust, iteratively reweighted estimate of
/// Wang et al. 2009, Eq. 9, on an OpenVDB grid in world space (or scalp space).
///
/// Every strand segment contributes its unit tangent T to **every voxel it passes through**
/// (SegmentWalk.h), weighted by its length ℓ inside that voxel. Iteration t (Eq. 9) weights each
/// contribution by ω = 0.5 (T · v̄_{t-1} + 1) and renormalizes, from v̄_0 = 0. Because ω is linear
/// in T, the weighted sum is exactly 0.5 (s + M v̄_{t-1}) with the per-voxel moments
/// s = Σ ℓ T and M = Σ ℓ T Tᵀ, so vdbhair walks the segments once, accumulates s and M, and
/// iterates per voxel: v̄_t = normalize(s + M v̄_{t-1}) — the same estimate, at the cost of one
/// pass however many iterations are asked for. The density is Σ ℓ = trace(M).
///
/// Voxels no segment passes stay inactive; a voxel whose contributions cancel keeps a zero vector
/// (tracing stops there, "vanished"). Two iterations is the default, as in the paper (more did
/// not change their results).
///
/// Determinism: strands are split into a fixed number of chunks (independent of the thread
/// count), each summed in strand order, and the chunks are merged in chunk order, so the grids
/// are bitwise identical with any number of threads.
#pragma once

#include <vdbhair/Memory.h>
#include <vdbhair/Parameters.h>
#include <vdbhair/field/FieldTypes.h>
#include <vdbhair/field/ScalpMap.h>
#include <vdbhair/strands/StrandSet.h>

#include <openvdb/Grid.h>
#include <openvdb/openvdb.h>
#include <openvdb/util/NullInterrupter.h>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace vdbhair {

struct FieldParams
{
    /// Most levels of estimateTangentFieldLevels() (level 15 has 32768 times the voxel size).
    static constexpr int kMaxLevels = 16;

    /// World units (>= 2e-5, OpenVDB's limit); in scalp space, world units at the scalp.
    /// 0 picks suggestVoxelSize() of the strands (resolveVoxelSize()).
    double voxelSize = 0.0;
    int iterations = 2;       ///< Eq. 9 iterations (>= 1)
    FieldSpace space = FieldSpace::World;
    ScalpSphere scalp;        ///< used in scalp space (the sphere: d ≡ 1) unless scalpSurface is set
    /// In scalp space, a scalp measured on a level set (ScalpMap.h, built at
    /// ScalpMap::kFieldResolution): w is the height above it, and its sphere replaces `scalp`.
    /// The grids carry its table, so readers rebuild the same mapping (FieldMapping.h).
    std::shared_ptr<const ScalpMap> scalpSurface;
    /// The parameterization's sphere: scalpSurface's when set, else `scalp`.
    const ScalpSphere& scalpSphere() const { return scalpSurface ? scalpSurface->sphere() : scalp; }
    /// Cap on the voxel visits the segments could need (an upper bound computed before any
    /// allocation): a bound on the work, about a minute on two cores at the cap. A voxel size far
    /// too small for the hairstyle fails with LimitError (naming maxVoxels). Memory is bounded by
    /// maxMemory: visits revisit voxels, so they say little about it (a 1,000,000-strand head at
    /// its default voxel size makes 370 million visits into 2 million voxels).
    std::uint64_t maxVoxels = std::uint64_t(1) << 32;
    /// The hair length per unit volume (world units^-2) that `density` maps to 1; 0 chooses it
    /// (see TangentField::density).
    double densityReference = 0.0;
    /// Bytes the work may hold at its peak; 0: the memory the system has available when it starts
    /// (availableMemoryBytes()). A request whose estimate (estimatePeakBytes()) is larger fails
    /// with LimitError before allocating; no limit (the largest value) skips the estimate.
    std::uint64_t maxMemory = 0;
    /// Also estimate TangentField::coherence and TangentField::spread (two more grids, which
    /// `refine` needs); false leaves them null (`vdbhair field`, which writes neither).
    bool coherenceAndSpread = true;
};

/// @brief Put @a params in scalp space for hair with @a roots: on @a sphere when given, else on
/// the sphere fitted to the roots with @a up; with @a surface (a scalp level set), w measured
/// above that surface (ScalpMap at ScalpMap::kFieldResolution, from the sphere fitted to the roots).
/// @throw ValueError for a sphere whose radius is not positive and finite, a sphere and a surface
/// both given, roots too few or too flat to fit a sphere, or a fitted centre outside the surface.
void useScalpSpace(FieldParams& params, const std::vector<Vec3f>& roots, const Vec3d& up, const ScalpSphere* sphere,
                   openvdb::FloatGrid::ConstPtr surface);

/// @brief What estimating a field at one voxel size will allocate, counted before it allocates
/// (estimateFieldFootprint()): the terms of the memory estimate.
struct FieldFootprint
{
    std::uint64_t strands = 0, vertices = 0;
    std::uint64_t visits = 0;  ///< an upper bound on the voxel visits (what FieldParams::maxVoxels caps)
    /// The 8^3 leaf blocks the segments pass through: every grid of the field has these leaves.
    /// Exact when the bounding box has at most 2^27 blocks (a byte each while counting), otherwise
    /// the upper bound min(visits, blocks of the bounding box).
    std::uint64_t leaves = 0;
};

/// @brief The footprint of estimating the field of @a strands at @a params (voxel size 0:
/// resolveVoxelSize()): one pass over the vertices for the bounds, one for the leaves.
/// @throw ValueError as estimateTangentField().
FieldFootprint estimateFieldFootprint(const StrandSet& strands, const FieldParams& params);

/// What a computation over the footprints holds at its peak (estimatePeakBytes()).
enum class MemoryUse
{
    Field,   ///< estimateTangentFieldLevels(): the strands, every level's grids, one level's chunks
    Refine,  ///< refineStrands() (Refine.h): also the output strands, the input's field, the retrace's bricks, the report
};

/// @brief The memory estimate: peak bytes of @a use over @a footprints (one per level, level 0
/// first), the sum of per-vertex, per-strand and per-leaf terms. The one home of the memory
/// model (its constants, in TangentField.cc, say what each term holds); fitted to the peak
/// resident memory of `vdbhair field` and `vdbhair refine` from 100,000 to 1,000,000 strands
/// (docs/performance.md, "Memory at scale"), which it stays a little above.
std::uint64_t estimatePeakBytes(const std::vector<FieldFootprint>& footprints, MemoryUse use);

/// @brief availableMemoryBytes(params.maxMemory) (Memory.h).
std::uint64_t availableMemoryBytes(const FieldParams& params);

/// @brief checkMemory() (Memory.h) against params.maxMemory, advising a larger voxel.
/// @param how the terms of the estimate, for the message
void checkMemoryEstimate(const char* where, std::uint64_t estimate, const std::string& how, const FieldParams& params);

/// @brief The grids of one level.
struct TangentField
{
    openvdb::Vec3SGrid::Ptr tangent;  ///< unit directions, root to tip; class unknown, contravariant relative
    /// A fog volume in [0, 1] a shader can use as it is: `min(1, hair_length / (h^3 rho))`, the
    /// hair length per unit volume in the voxel (h: the voxel size in world units, at the scalp in
    /// scalp space) over the reference rho (world units^-2). rho is FieldParams::densityReference
    /// when given (the same value gives the same meaning at any voxel size and for any
    /// hairstyle), otherwise the 95th percentile of hair_length / h^3 over the active voxels (of
    /// level 0 for multi-level fields, used for every level): 1 then means "as dense as the
    /// densest 5% of this hairstyle". The value used is the grid's `vdbhair_density_reference`.
    openvdb::FloatGrid::Ptr density;
    openvdb::FloatGrid::Ptr hairLength;  ///< summed segment length per voxel (world units); class unknown
    double densityReference = 0.0;       ///< rho, as used for `density`
    /// |Σ ℓ T| / Σ ℓ per voxel, in [0, 1]: 1 where every contribution points the same way, near 0
    /// where they cancel (crossing or opposing strands); class unknown, same topology as tangent.
    openvdb::FloatGrid::Ptr coherence;
    /// The contributions' mean squared sine of their angle to the robust direction v̄:
    /// 1 − v̄ᵀ M v̄ / Σ ℓ, in [0, 1] (0: all parallel to v̄); how far a strand's own direction may
    /// stray from v̄ before it is an outlier (Refine.h). Class unknown, same topology as tangent.
    openvdb::FloatGrid::Ptr spread;

    /// @brief The five grids (tangent, density, hair_length, coherence, spread), for writing.
    openvdb::GridCPtrVec grids() const;
};

/// @brief The default finest voxel size of a hairstyle, from its own scale: three times the
/// median distance between neighbouring roots (so that a voxel near the scalp holds about nine
/// strands, enough for a robust direction and its spread), kept between 1/64 and 1/4 of the head
/// radius (the radius of the sphere fitted to the roots, or half the hair's largest extent when
/// that fit is implausible) so that the finest level resolves wisps whatever the strand count.
/// Coarser levels double it, as Wang et al. halve their spacing from coarse to fine.
/// (Defined in Refine.cc, with the root-sphere fit it shares with headFromRoots().)
/// @throw ValueError for an empty hairstyle.
double suggestVoxelSize(const StrandSet& strands);

/// @brief The voxel size an estimate at @a params uses: params.voxelSize, or
/// suggestVoxelSize(@a strands) when it is 0 (the one place that rule lives).
double resolveVoxelSize(const StrandSet& strands, const FieldParams& params);

/// @brief The field estimate's parameters (Parameters.h), declared once: `field` and
/// estimate_tangent_field() offer them (fieldLevelsParameters()), and `refine` reuses those it
/// shares (its fields', the space and the up axis).
/// Defaults are FieldParams{}'s.
const ParamTable<FieldParams>& fieldParameters();

/// `field`'s parameters: the estimate's and the number of levels (estimateTangentFieldLevels()).
struct FieldLevelsParams
{
    FieldParams field;
    int levels = 1;  ///< 1 to FieldParams::kMaxLevels; level l has voxel size field.voxelSize · 2^l
};

/// @brief field's parameters declared once: fieldParameters() and the levels (Python's
/// estimate_tangent_field(levels=None) returns one field rather than a list of one).
const ParamTable<FieldLevelsParams>& fieldLevelsParameters();

/// @brief Estimate the field of @a strands at one voxel size (params.voxelSize, 0: resolveVoxelSize()).
/// @throw ValueError (empty hairstyle, voxel size negative or not finite, iterations < 1),
/// LimitError (the voxel bound exceeds params.maxVoxels; the message says the estimate and the
/// cap and names maxVoxels), InterruptedError.
/// @warning Thread-safe for concurrent calls on different outputs.
TangentField estimateTangentField(const StrandSet& strands, const FieldParams& params,
                                  bool threaded = true, openvdb::util::NullInterrupter* interrupter = nullptr);

/// @brief Multi-level fields: level l has voxel size params.voxelSize · 2^l (Wang et al. halve the
/// spacing from level to level); element l of the result is level l (0 the finest). Grids are
/// named with tangentGridName(l, levels) / densityGridName(l, levels).
/// @throw as estimateTangentField(); ValueError for @a levels outside [1, FieldParams::kMaxLevels].
std::vector<TangentField> estimateTangentFieldLevels(const StrandSet& strands, const FieldParams& params,
                                                     int levels, bool threaded = true,
                                                     openvdb::util::NullInterrupter* interrupter = nullptr);

/// @brief estimateTangentField(@a strands, @a params) after the memory check of @a use over
/// @a levels levels from its voxel size (estimatePeakBytes(), refused as checkMemoryEstimate()
/// does, naming @a where), one pass over the strands serving both: how refineStrands() checks
/// the whole refinement before its first field. @a footprints receives each level's footprint,
/// its leaves exact (estimateFieldFootprint()'s). Unlike estimateTangentField(), it checks even
/// without a limit (params.maxMemory at its largest), since the footprints are asked for.
/// @throw as estimateTangentField(); LimitError above the memory available.
TangentField estimateTangentFieldAfterCheck(const StrandSet& strands, const FieldParams& params, MemoryUse use, int levels,
                                            const char* where, std::vector<FieldFootprint>& footprints, bool threaded = true,
                                            openvdb::util::NullInterrupter* interrupter = nullptr);

/// @brief An upper bound on the voxel visits of estimating at @a params (what maxVoxels caps).
std::uint64_t estimateVoxelVisits(const StrandSet& strands, const FieldParams& params);

} // namespace vdbhair
