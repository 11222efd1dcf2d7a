/// @file HelicoidField.h
/// @brief Helicoid fields in VDB: where a tangent field says where hair goes, a helicoid field
/// also says how it turns. Every active voxel holds a generalized helicoid (Piuze et al. 2011,
/// Eq. 1) fitted to the directions of its neighbours; tracing blends the exact predictions of
/// the surrounding voxels' helicoids, so a coarse grid can still follow curls.
///
/// Grids (docs/helicoids.md): `helicoid_k` (vec3s: kT, kN, kB; invariant), `helicoid_alpha` (float),
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

/// @brief Fit a helicoid at every active voxel of a world-space tangent field to the strands it
/// was estimated from (issue 19): the helicoid sees each strand's own curl, not the average of
/// the strands that share a voxel, where curls with different phases cancel.
///
/// Data: every piece of every strand segment inside a voxel (the tangent field's walk,
/// SegmentWalk.h), at its midpoint, with the strand's tangent there (vertex tangents, the mean
/// of the adjacent chords, interpolated along the segment). A voxel's helicoid is fitted to the
/// pieces in it and its 26 neighbours, weighted by length times a tent that reaches zero 1.5
/// voxels from the centre on each axis (the tracer uses a voxel's helicoid up to one voxel away).
/// Fit: in a frame (t, n, b), theta = atan2(d·n, d·t) and phi = asin(d·b) of each piece are fitted
/// by weighted least squares as c + g · y (y its offset from the voxel centre; a ridge of 1 % of
/// the weight on g, so directions the pieces do not span get no gradient), three times: first
/// with t the field's direction and Eq. 9's weight 0.5 (d·t + 1) (Wang et al. 2009) raised to
/// the 16th power, then with t re-centred on the fitted direction at the voxel centre and the
/// weight (0.5 (d·d̂ + 1))^16 against the direction d̂ the previous fit predicts at the piece. The
/// power makes the fit follow one family of strands where several cross (Eq. 9 as written keeps
/// half the weight of a perpendicular strand); powers 1, 4, 8, 16 and 32 were measured and 16
/// retraced closest overall (issue 19's figures in the commit). Pieces pointing backwards (d·t <= 0)
/// are ignored. Helicoid (Eq. 1 to first order, d(y) = t + (k·y) N): the best rank-1 part of the
/// 2x3 gradient of (theta, phi) (its largest singular pair) gives N and k, with kT >= 0 where the
/// flow curves; alpha = 0. Where that gradient is below 1e-3 / voxel, k = 0 and N =
/// perpendicularTo(t). Results do not depend on the thread count (pieces are ordered by voxel,
/// then strand).
/// @param strands the world-space strands @a tangent was estimated from
/// @throw TypeError / ValueError for a grid that is not a world-space vec3s tangent field.
/// @param interrupter optional progress and Ctrl-C (Progress.h); InterruptedError when it stops the work.
HelicoidFieldGrids estimateHelicoidField(const StrandSet& strands, const openvdb::Vec3SGrid& tangent, bool threaded = true,
                                         openvdb::util::NullInterrupter* interrupter = nullptr);

/// @brief Fit a helicoid at every active voxel of a world-space tangent field, from the field
/// alone (for a field read from a file, without its strands; the overload above fits the strands
/// and retraces more closely, docs/helicoids.md, "Helicoid fields in VDB").
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

/// The integrator `vdbhair retrace --helicoid` uses unless told otherwise (the tangent field's
/// default stays TraceParams' Euler). A helicoid field is for accuracy on curls, and forward Euler
/// at half a voxel is not: its own error on a curl (the same through either field) hid the
/// helicoid field's gain, 0.86-0.99x the tangent field's accuracy on Fig. 5's curls at Euler
/// against 1.25-1.73x with RK4 for both (benchmark, helicoid-field section; docs/helicoids.md, "Helicoid
/// fields in VDB"). RK4 costs `retrace --helicoid` about 1.7 times Euler's time end to end
/// (4,933 strands: 0.22 s against 0.13 s).
inline constexpr Integrator kHelicoidRetraceIntegrator = Integrator::RK4;

/// @brief Retrace strands through a helicoid field: at a point, each active corner of the
/// sampling cell predicts a direction by evaluating its own helicoid (the exact Eq. 1, origin at
/// the voxel centre) at that point, and the predictions are blended with the trilinear weights to
/// the 8th power and normalized (HelicoidFieldSampler). params.integrator is used as given (the
/// command's default for this retrace is kHelicoidRetraceIntegrator). The streamline engine's general path (SamplerRetrace.h):
/// same parameters, stop rules, write-out and statistics as retraceStrands() (params.kernel is
/// ignored: there is no lane kernel for helicoid fields).
/// @param interrupter optional progress and Ctrl-C (Progress.h).
/// @throw ValueError (TraceParams::validate(): a negative step, a margin or vanish threshold out
/// of range), InterruptedError when the interrupter stops the work.
StrandSet retraceHelicoidField(const StrandSet& strands, const HelicoidFieldGrids& field, const TraceParams& params,
                               TraceStats* stats = nullptr, bool threaded = true,
                               openvdb::util::NullInterrupter* interrupter = nullptr);

} // namespace vdbhair
