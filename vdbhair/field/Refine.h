/// @file Refine.h
/// @brief Vector-field refinement (Wang et al. 2009, §5.3): estimate the robust tangent field of
/// a hairstyle, retrace every strand from its root through it, and repeat from the coarsest level
/// to the finest (voxel size h·2^(levels-1) down to h).
///
/// Two modes (RefineMode):
/// - **consistent** (the default) keeps the hairstyle and fixes only its inconsistencies: each
///   level retraces the previous level's strands with ConsistentRetrace.h, which follows the
///   field only where a strand is an outlier among the hair around it, and otherwise the strand's
///   own direction. Strands keep their detail (waves, curls, crossing wisps) through any number
///   of levels, their length and vertex count, and never enter the head deeper than they were.
///   This goes beyond the paper; docs/fields.md, "Refinement", shows both modes on the shared hair.
/// - **field** is the paper's rule: every strand is replaced by the streamline of the field from
///   its root, for its own length (StreamlineTracer.h). It smooths everything at the voxel's
///   scale: waves are combed straight and crossing wisps are merged. Strands stop where the
///   field ends (margin 0: no straight spikes past the hair).
///
/// The default voxel size follows the hair's own scale (suggestVoxelSize(), TangentField.h).
#pragma once

#include <vdbhair/Parameters.h>

#include <vdbhair/field/ConsistentRetrace.h>
#include <vdbhair/field/HeadObstacle.h>
#include <vdbhair/field/RefineReport.h>
#include <vdbhair/field/StreamlineTracer.h>
#include <vdbhair/field/TangentField.h>

#include <string>
#include <vector>

namespace vdbhair {

enum class RefineMode { Consistent, Field };

/// @throw ValueError unless "consistent" or "field".
RefineMode refineModeFromName(const std::string& name);
const char* refineModeName(RefineMode mode);

struct RefineParams
{
    static constexpr int kMaxLevels = 8;  ///< each level costs an estimate and a retrace

    FieldParams field;  ///< field.voxelSize is the finest level's; 0 picks suggestVoxelSize()
    int levels = 1;     ///< 1 to kMaxLevels
    RefineMode mode = RefineMode::Consistent;
    ConsistencyParams consistency;  ///< the consistent mode's retrace
    /// The field mode's retrace: step 0 is half of each level's voxel; margin 0, so strands stop
    /// where the field ends instead of continuing straight past the hair.
    TraceParams trace = [] {
        TraceParams t;
        t.margin = 0;
        return t;
    }();
    /// The head retraced strands may not enter. Unset: a sphere fitted to the roots (headFromRoots());
    /// HeadObstacle::none(): no head.
    HeadObstacle head;
    /// The policy of a head the front end gives (a file, a sphere, the scalp): what it makes
    /// @c head with (refine's `--head-policy`); the head fitted to the roots keeps its own.
    HeadPolicy headPolicy = kDefaultHeadPolicy;
    /// Fill RefineLevel::measures: the output against the input (costs a field estimate per level,
    /// a fifth of the run; `refine --measure`).
    bool measure = false;

    /// @brief One step rule for both modes (the CLI's --step and --integrator): the step (world
    /// units; 0: half of each level's voxel) and the integrator of trace and consistency.
    void setStep(double step, Integrator integrator);

    /// @throw ValueError naming the parameter for values out of range.
    void validate(const char* where) const;
};

/// @brief refine's parameters (Parameters.h): the one declaration the command line, Python and
/// docs/cli.md are made from. Defaults are RefineParams{}'s.
const ParamTable<RefineParams>& refineParameters();

/// @brief What happened at one level.
struct RefineLevel
{
    double voxelSize = 0.0;
    ConsistencyStats consistency;  ///< consistent mode
    TraceStats trace;              ///< field mode
    RefineMeasures measures;       ///< this level's output against the *input*, at the finest voxel size
};

/// @brief The memory estimate of a refinement (estimateRefineMemory()).
struct RefineMemory
{
    std::uint64_t bytes = 0;                 ///< the estimated peak
    std::uint64_t available = 0;             ///< what it was checked against (availableMemoryBytes())
    std::vector<FieldFootprint> footprints;  ///< element l: level l (0 the finest)
};

/// @brief The peak bytes of refineStrands(@a strands, @a params), before anything is allocated:
/// each level's footprint (estimateFieldFootprint()) and estimatePeakBytes(MemoryUse::Refine)
/// over them. The voxel size is resolved as refineStrands() does.
/// @throw ValueError as refineStrands(); LimitError above FieldParams::maxVoxels.
RefineMemory estimateRefineMemory(const StrandSet& strands, const RefineParams& params);

struct RefineResult
{
    StrandSet strands;                 ///< the refined hairstyle (input vertex counts)
    std::vector<TangentField> fields;  ///< element l: level l (0 the finest), the field the strands were traced through
    std::vector<RefineLevel> levels;   ///< element l: level l
    double voxelSize = 0.0;            ///< the finest voxel size used
    HeadObstacle head;                 ///< the obstacle used
    RefineMemory memory;               ///< the estimate checked before anything was allocated
};

/// @brief The fallback head: the sphere fitted to the roots (fitScalpSphere()) with the up axis @a up.
HeadObstacle headFromRoots(const StrandSet& strands, const Vec3d& up = Vec3d(0.0, 1.0, 0.0));

/// Refuses up front (LimitError naming the estimate, the memory available and the rule) when
/// estimateRefineMemory() exceeds availableMemoryBytes(params.field).
/// @throw as estimateTangentField(), retraceStrands() and retraceConsistent(); ValueError for
/// parameters out of range; LimitError (memory, above).
RefineResult refineStrands(const StrandSet& strands, const RefineParams& params, bool threaded = true,
                           openvdb::util::NullInterrupter* interrupter = nullptr);

/// @brief refineStrands() of a hairstyle the caller no longer needs: the same result, bit for bit.
/// Consistent mode without RefineParams::measure retraces into the input's own storage instead of a
/// copy of it (a 100,000 x 64 set: 77 MB less, and no serial copy). @a strands is left in a valid
/// but unspecified state, also when an exception is thrown.
RefineResult refineStrands(StrandSet&& strands, const RefineParams& params, bool threaded = true,
                           openvdb::util::NullInterrupter* interrupter = nullptr);

} // namespace vdbhair
