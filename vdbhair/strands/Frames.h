/// @file Frames.h
/// @brief Discrete frames along a polyline: Frenet frames and parallel-transport
/// (rotation-minimizing) frames.
#pragma once

#include <vdbhair/Types.h>

#include <cstddef>

namespace vdbhair {

/// @brief A unit vector perpendicular to @a t, chosen stably: @a t crossed with the world axis
/// least aligned with it. The fallback normal wherever curvature does not define one.
Vec3f perpendicularTo(const Vec3f& t);

/// @brief Discrete Frenet frames at each of the @a n points (Ros03, as Piuze et al. use for
/// fitting): t from computeTangents(), b along e_{i-1} x e_i, n = b x t.
///
/// Where the polyline is locally straight the binormal is undefined; there the frame carries the
/// last defined normal (projected to the new tangent), before the first curved vertex it takes
/// that vertex's normal, and on a fully straight polyline n = perpendicularTo(t).
/// Endpoints take the normal of their interior neighbour. Frames are right-handed orthonormal.
void frenetFrames(const Vec3f* points, std::size_t n, Frame* out);

/// @brief Rotation-minimizing frames by the double-reflection method
/// (Wang, Jüttler, Zheng, Liu 2008), starting from @a initialNormal at the root
/// (projected onto the plane normal to the root tangent).
void parallelTransportFrames(const Vec3f* points, std::size_t n, const Vec3f& initialNormal,
                             Frame* out);

/// @brief As above, starting from the Frenet normal at the root.
void parallelTransportFrames(const Vec3f* points, std::size_t n, Frame* out);

} // namespace vdbhair
