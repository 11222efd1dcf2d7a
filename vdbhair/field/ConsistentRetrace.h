/// @file ConsistentRetrace.h
/// @brief Retracing that fixes only a hairstyle's inconsistencies: every strand is retraced from
/// its root through the robust tangent field (Wang et al. 2009, §5.3), but at each step the
/// direction blends the strand's own direction with the field's by how much of an *outlier* the
/// strand is there. Each sub-step is a step of the streamline engine (Streamline.h) through that
/// blended direction: forward Euler by default, RK2/RK3/RK4 with ConsistencyParams::integrator. This goes beyond the paper (see below and docs/fields.md, "Refinement").
///
/// Wang et al. replace every strand by a streamline of the field. On real hair that combs waves
/// and curls straight (the field averages strands of different phase), swaps crossing wisps (a
/// single-valued field holds one direction per voxel) and sends strands that leave the field off
/// straight. Here a strand is retraced segment by segment, each input segment in sub-steps of at
/// most `step`, and a sub-step at p with the strand's own unit direction t moves along
///
///     d = normalize((1 − w) t + w v̄),   w = smoothstep(zStart, zFull, z),   z = δ / σ,
///
/// where v̄ is the field's direction at p, δ = sin∠(t, v̄) (1 if t points against v̄) is how far
/// the strand strays from it, and σ = sqrt(spread) the root-mean-square sine of the voxel's own
/// contributions to v̄ (TangentField::spread), floored at sin(minSpreadDeg). z is a robust
/// z-score: a strand that strays no more than its neighbours do (waves and curls of different
/// phase, crossing wisps: both directions are part of the spread) keeps its own direction; one
/// that strays far more than they do (a stray strand in a combed bundle) follows the field. For a
/// minority of fraction f against a perfectly aligned majority, z = 1/sqrt(f): with the defaults
/// (2 and 4) a direction held by more than a quarter of a voxel's hair is never overruled, one
/// held by less than 1/16 always is. Where there is no field (outside its active region, or
/// where it vanishes) the strand keeps its own direction: no straight spikes, no early stops.
///
/// A field pointing back along the strand (δ = 1) would turn it round where it is an outlier. By
/// default (ConsistencyParams::followOpposed false) w fades to 0 as ∠(t, v̄) goes from 90 to 110
/// degrees instead: opposite directions in a voxel are taken for two flows (the sides of a parting,
/// the halves of a curl finer than the voxel), not an error. Following the other flow folds strands
/// back on themselves: in synthesis, where a level's field averages curls finer than its voxel
/// (Curly_100's curls transferred onto straight.hair: 728 strands with a turn over 120 degrees
/// between two edges, 72 with the fade; a synthesized strand of Sintel's hair turned round into a
/// spike above the head), and in refine on real hair (the free ponytail: 3 strands folded by
/// 124-149 degrees, HairNet's blend 1; none with the fade, on 11 shared hairstyles).
///
/// A correction moves the rest of the strand with it; so the strand's own direction t is steered
/// back toward the input strand at the same arc length (by offset / (returnVoxels · h) per unit
/// length): a stray kink is straightened where it is, and the strand rejoins its own path after
/// it, instead of carrying the correction to its tip.
///
/// A step that would leave the field's active region (the hair volume) heads for the input
/// strand's own point at the step's end instead: corrected strands stay in the hair. A retraced
/// strand that still leaves the hair volume dilated by a voxel (HairVolume.h: the output chords
/// can cut across a gap, a slide along the head can carry it out) is left as it was.
///
/// Where the strand's own direction wins at every sub-step of an input segment (and, for a
/// KeepOutside head, every sub-step ends outside it), the retrace of that segment from its first
/// vertex is, in exact arithmetic, the segment itself. With forward Euler such a segment, reached
/// on the input strand, is taken from the input bit for bit rather than traced (its points'
/// samples are independent, where the trace waits for each sub-step's end); a traced vertex that
/// rounds to the input's puts the strand back on it. Most segments of real hair are such.
///
/// Output strands keep the input's vertex count and segment lengths (so every strand has its
/// full length), and the head is an obstacle: its HeadPolicy says whether retraced vertices must
/// stay outside it or only no deeper inside than the input's (HeadObstacle.h). Strands are independent: results do not depend on the thread count.
#pragma once

#include <vdbhair/field/HeadObstacle.h>
#include <vdbhair/field/Streamline.h>
#include <vdbhair/field/TangentField.h>
#include <vdbhair/strands/StrandSet.h>

#include <openvdb/util/NullInterrupter.h>

#include <cstddef>

namespace vdbhair {

struct ConsistencyParams
{
    double step = 0.0;         ///< world units; 0: kDefaultStepVoxels (half a voxel) of the field's voxel size
    double zStart = 2.0;       ///< outlier score where the field starts to take over (see the file comment)
    double zFull = 4.0;        ///< outlier score from which the field's direction is followed
    double minSpreadDeg = 3.0; ///< floor on a voxel's angular spread, degrees: deviations below it are never outliers
    /// voxels over which a strand that a correction moved off its own path steers back to it
    /// (the own direction t becomes t + offset / (returnVoxels · voxel size), renormalized)
    double returnVoxels = 4.0;
    double vanishThreshold = kDefaultVanishThreshold;  ///< as TraceParams::vanishThreshold
    /// the engine's step through the blended direction (Streamline.h); each stage blends the
    /// strand's own direction of the sub-step with the field's at the stage's point
    Integrator integrator = Integrator::Euler;
    /// A field pointing back along the strand (more than 90 degrees from it): false, its pull fades
    /// out from 90 to 110 degrees (see the file comment); true, it pulls as any other and may turn
    /// the strand round, as Wang et al.'s streamlines would.
    bool followOpposed = false;

    /// @throw ValueError (parameter @a where names the offender) for values out of range.
    void validate(const char* where) const;
};

struct ConsistencyStats
{
    std::size_t strands = 0;
    std::size_t corrected = 0;     ///< strands with at least one sub-step where the field took over (w ≥ 0.5)
    std::size_t steps = 0;         ///< sub-steps in all
    std::size_t fieldSteps = 0;    ///< sub-steps with w ≥ 0.5
    std::size_t noFieldSteps = 0;  ///< sub-steps outside the field or where it vanishes (own direction)
    std::size_t pushedOut = 0;     ///< segments whose end was moved back out of the head on the way
    std::size_t heldIn = 0;        ///< sub-steps that would have left the field, turned toward the input strand
    /// strands left as they were (out of the head if the policy says so) because their retrace
    /// left the hair volume (HairVolume.h) where the input did not; not counted as corrected
    std::size_t reverted = 0;
};

/// @brief Retrace @a strands through @a field as described in the file comment.
/// @param field tangent and spread grids of one level (estimateTangentField())
/// @param head optional obstacle (an empty HeadObstacle: none)
/// @param hairVolume optional grid whose active voxels are the hair volume strands are held in
/// (default: @a field's own active region; refinement passes the input's finest field, so that
/// coarse levels do not let strands wander out of the finest hair volume)
/// @throw ValueError (bad parameters, a field without its spread grid), InterruptedError.
StrandSet retraceConsistent(const StrandSet& strands, const TangentField& field, const ConsistencyParams& params,
                            const HeadObstacle& head = HeadObstacle(), ConsistencyStats* stats = nullptr,
                            bool threaded = true, openvdb::util::NullInterrupter* interrupter = nullptr,
                            const openvdb::Vec3SGrid* hairVolume = nullptr);

/// @brief retraceConsistent() of @a strands into their own storage: the same result, bit for bit,
/// without a second copy of the positions (each strand is traced into a buffer of its own and
/// then written over its input; no strand's trace reads another's vertices).
StrandSet retraceConsistent(StrandSet&& strands, const TangentField& field, const ConsistencyParams& params,
                            const HeadObstacle& head = HeadObstacle(), ConsistencyStats* stats = nullptr,
                            bool threaded = true, openvdb::util::NullInterrupter* interrupter = nullptr,
                            const openvdb::Vec3SGrid* hairVolume = nullptr);

} // namespace vdbhair
