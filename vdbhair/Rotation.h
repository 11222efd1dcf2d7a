/// @file Rotation.h
/// @brief The library's rotations of vectors: Rodrigues' formula about a unit axis, by a rotation
/// vector, and the shortest rotation taking one direction onto another.
///
/// Vectors are turned by Rodrigues' formula, v c + (k × v) s + k (k · v)(1 - c), rather than by
/// OpenVDB's openvdb::math::rotation<Mat3d>(axis, angle) applied as a matrix: the matrix re-normalizes
/// the axis and sums its products in another order, so its results differ in the last bits, and
/// most callers have the cosine and sine already (a dot and a cross product). The shortest
/// rotation as a matrix is OpenVDB's (rotationMatrixBetween()).
#pragma once

#include <vdbhair/Types.h>

#include <openvdb/math/Mat3.h>

#include <cmath>

namespace vdbhair {

/// @brief @a v turned about the unit @a axis by the angle whose cosine and sine are @a c and @a s
/// (Rodrigues' formula; right-handed: a positive angle turns x toward y about z).
inline Vec3d rotateAbout(const Vec3d& v, const Vec3d& axis, double c, double s)
{
    return v * c + axis.cross(v) * s + axis * (axis.dot(v) * (1.0 - c));
}

/// @brief @a v turned about the unit @a axis by @a angle radians.
inline Vec3d rotateAbout(const Vec3d& v, const Vec3d& axis, double angle)
{
    return rotateAbout(v, axis, std::cos(angle), std::sin(angle));
}

/// @brief @a v turned by the rotation vector @a r (its direction the axis, its length the angle in
/// radians); @a v itself when @a r is zero.
inline Vec3d rotateByVector(const Vec3d& v, const Vec3d& r)
{
    const double angle = r.length();
    if (!(angle > 0.0)) return v;
    return rotateAbout(v, r / angle, angle);
}

/// @brief @a v turned half a turn about the unit @a axis (exactly: its reflection through the axis).
inline Vec3d halfTurn(const Vec3d& v, const Vec3d& axis) { return axis * (2.0 * axis.dot(v)) - v; }

/// @brief The shortest rotation taking the unit @a from onto the unit @a to: sets the unit @a axis
/// (along from × to) and the cosine @a c and sine @a s of the angle. @return false, with only @a c
/// set, when the two are parallel or opposite (|from × to| < 1e-12): no axis is then the one
/// shortest (opposite directions are a half turn about any perpendicular).
inline bool shortestRotation(const Vec3d& from, const Vec3d& to, Vec3d& axis, double& c, double& s)
{
    axis = from.cross(to);
    s = axis.length();
    c = from.dot(to);
    if (s < 1e-12) return false;
    axis /= s;
    return true;
}

/// @brief @a v turned by the shortest rotation taking the unit @a from onto the unit @a to; when
/// they are parallel, @a v; when opposite, @a v turned half a turn about the unit @a halfTurnAxis
/// (the caller's choice of perpendicular).
inline Vec3d rotateOnto(const Vec3d& from, const Vec3d& to, const Vec3d& v, const Vec3d& halfTurnAxis)
{
    Vec3d axis;
    double c, s;
    if (shortestRotation(from, to, axis, c, s)) return rotateAbout(v, axis, c, s);
    return c > 0.0 ? v : halfTurn(v, halfTurnAxis);
}

/// @brief The rotation vector (unit axis times the angle in radians, atan2(|a × b|, a · b)) of the
/// shortest rotation taking the unit @a a onto the unit @a b; zero when they are parallel or
/// opposite (|a × b| <= 1e-12: a half turn has no one axis).
inline Vec3d rotationVectorBetween(const Vec3d& a, const Vec3d& b)
{
    const Vec3d axis = a.cross(b);
    const double s = axis.length(), c = a.dot(b);
    if (!(s > 1e-12)) return Vec3d(0.0);
    return axis * (std::atan2(s, c) / s);
}

/// @brief The shortest rotation taking the unit @a a onto the unit @a b as a matrix (OpenVDB's
/// openvdb::math::rotation(v1, v2)). OpenVDB matrices act on row vectors: apply it with
/// transform() (R.transform(a) == b).
inline openvdb::math::Mat3d rotationMatrixBetween(const Vec3d& a, const Vec3d& b)
{
    return openvdb::math::rotation<openvdb::math::Mat3d>(a, b);
}

} // namespace vdbhair
