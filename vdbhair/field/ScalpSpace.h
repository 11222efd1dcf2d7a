/// @file ScalpSpace.h
/// @brief Wang et al.'s scalp space (2009, §3, Eq. 1-2): a parameterization (u, v, w) of the hair
/// volume above a spherical scalp, with its only singularity at the sphere's south pole.
///
/// World points are first expressed in the sphere's frame: p' = R⁻¹ (p - center) / radius, where
/// R rotates the +y axis onto the scalp's `up` direction (the paper's y-up convention). Then, with
/// (x̂, ŷ, ẑ) = p' / |p'|:
///   u = arccos(x̂ / sqrt(x̂² + (ŷ+1)²)),  v = arccos(ẑ / sqrt(ẑ² + (ŷ+1)²)),  w = |p'| - 1
/// (the scalp is the unit sphere, so d = 1). u and v are angles in (0, π) measured from the
/// south pole S0 = (0, -1, 0); w is the height above the scalp in units of the radius.
/// The inverse (Eq. 2): h = 2 / (cot²u + cot²v + 1), (x̂, ŷ, ẑ) = (h cot u, h - 1, h cot v),
/// p' = (w + 1)(x̂, ŷ, ẑ).
///
/// @warning Near the south pole (points below the head: draped hair) u and v crowd towards 0 or
/// π and the mapping's distortion grows without bound; that is the limitation of Wang et al. that
/// vdbhair's default world-space fields avoid.
#pragma once

#include <vdbhair/Types.h>

#include <vector>

namespace vdbhair {

/// @brief A spherical scalp: centre and radius in world units, and the world direction of "up".
struct ScalpSphere
{
    Vec3d center{0.0};
    double radius = 1.0;
    Vec3d up{0.0, 1.0, 0.0};  ///< unit
};

/// @brief Scalp-space coordinates (u, v, w) of a world point (Eq. 1).
/// At the exact south pole (and the centre) the result is clamped to the nearest valid values.
Vec3d worldToScalp(const ScalpSphere& scalp, const Vec3d& world);

/// @brief World point of scalp-space coordinates (u, v, w) (Eq. 2).
Vec3d scalpToWorld(const ScalpSphere& scalp, const Vec3d& uvw);

/// @brief Least-squares sphere through @a points (algebraic fit: |p|² = 2 c·p + k), with @a up.
/// @throw ValueError with fewer than 4 points or points on a plane or line.
ScalpSphere fitScalpSphere(const std::vector<Vec3f>& points, const Vec3d& up = Vec3d(0.0, 1.0, 0.0));

} // namespace vdbhair
