/// @file HelicoidField.h
/// @brief Helicoid fields in VDB: where a tangent field says where hair goes, a helicoid field
/// also says how it turns. Every active voxel holds a generalized helicoid (Piuze et al. 2011,
/// Eq. 1) fitted to the directions of its neighbours; tracing blends the exact predictions of
/// the surrounding voxels' helicoids, so a coarse grid can still follow curls.
///
/// Grids (DESIGN.md): `helicoid_k` (vec3s: kT, kN, kB; invariant), `helicoid_alpha` (float),
/// `frame_T` and `frame_N` (vec3s, contravariant relative; B = T x N), all with the topology of
/// the tangent field they come from.
#pragma once

#include <openvdb/util/NullInterrupter.h>

#include <vdbhair/field/StreamlineTracer.h>
#include <vdbhair/strands/StrandSet.h>

#include <openvdb/openvdb.h>

#include <string>

namespace vdbhair {

struct HelicoidFieldGrids
{
    openvdb::Vec3SGrid::Ptr k;      ///< helicoid_k
    openvdb::FloatGrid::Ptr alpha;  ///< helicoid_alpha
    openvdb::Vec3SGrid::Ptr frameT; ///< frame_T
    openvdb::Vec3SGrid::Ptr frameN; ///< frame_N
};

/// @brief Fit a helicoid at every active voxel of a world-space tangent field.
///
/// Frame: T is the field's direction; N is the direction of the flow's curvature vector
/// (T·∇)T, estimated by central differences of the trilinearly sampled field one voxel ahead and
/// behind along T, where its magnitude exceeds 1e-3 / voxel; elsewhere (straight flow, where the
/// curvature direction is noise) N = perpendicularTo(T), a stable documented choice. B = T x N.
/// Parameters: with the active 26 neighbours j at local offsets y_j = Qᵀ (x_j - x) and their
/// directions expressed in the frame as angles theta_j = atan2(d·N, d·T), phi_j = asin(d·B),
/// (kT, kN, kB) minimize Σ (theta_j - (kT y1 + kN y2 + kB y3))² (Eq. 1 to first order) with a
/// tiny ridge for conditioning, and alpha minimizes Σ (phi_j - alpha theta_j)². Neighbours
/// pointing backwards (d·T <= 0) are ignored; with fewer than 3 neighbours k = alpha = 0.
/// @throw TypeError / ValueError for a grid that is not a world-space vec3s tangent field.
/// @param interrupter optional progress and Ctrl-C (Progress.h); InterruptedError when it stops the work.
HelicoidFieldGrids estimateHelicoidField(const openvdb::Vec3SGrid& tangent, bool threaded = true,
                                         openvdb::util::NullInterrupter* interrupter = nullptr);

/// @brief Read `helicoid_k`, `helicoid_alpha`, `frame_T`, `frame_N` from a .vdb file.
/// @throw LookupError naming the missing grid (and estimateHelicoidField(), which makes them).
HelicoidFieldGrids readHelicoidField(const std::string& path);

/// @brief Retrace strands through a helicoid field: at a point, each active corner of the
/// sampling cell predicts a direction by evaluating its own helicoid (the exact Eq. 1, origin at
/// the voxel centre) at that point, and the predictions are blended with trilinear weights and
/// normalized (HelicoidFieldSampler). The streamline engine's general path (SamplerRetrace.h):
/// same parameters, stop rules, write-out and statistics as retraceStrands() (params.kernel is
/// ignored: there is no lane kernel for helicoid fields).
/// @param interrupter optional progress and Ctrl-C (Progress.h).
/// @throw ValueError (TraceParams::validate(): a negative step, a margin or vanish threshold out
/// of range), InterruptedError when the interrupter stops the work.
StrandSet retraceHelicoidField(const StrandSet& strands, const HelicoidFieldGrids& field, const TraceParams& params,
                               TraceStats* stats = nullptr, bool threaded = true,
                               openvdb::util::NullInterrupter* interrupter = nullptr);

} // namespace vdbhair
