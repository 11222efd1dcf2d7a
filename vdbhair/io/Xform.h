/// @file Xform.h
/// @brief Transforms of the scene formats as one 4x4 matrix: Alembic's `Xform` operations, as
/// AbcGeom's `XformSample::getMatrix` composes them, and USD's `xformOp`s, as
/// `UsdGeomXformable::GetLocalTransformation` does (AbcFile.h and UsdFile.h apply the parents'
/// matrices to the points they read).
#pragma once

#include <vdbhair/Types.h>

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace vdbhair {
namespace xform {

/// A 4x4 matrix in Imath's and USD's convention: row vectors, p' = p M, translation in row 3.
using Matrix = std::array<double, 16>;
constexpr Matrix kIdentity{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};

/// @brief The product a b (apply a, then b, to row vectors).
Matrix multiply(const Matrix& a, const Matrix& b);

/// @brief The rotation by @a degrees about the axis (x, y, z), counterclockwise looking down the
/// axis (right-handed), in row-vector form (Imath's Matrix44::setAxisAngle).
Matrix axisAngle(double x, double y, double z, double degrees);

/// @brief The inverse of @a m, or false when it is singular.
bool invert(const Matrix& m, Matrix& out);

/// @brief How much @a m scales lengths on average: the cube root of its 3x3 part's |determinant|
/// (what a curve's width is multiplied by).
double lengthScale(const Matrix& m);

/// @brief The matrix of Alembic @a ops (one byte each, AbcGeom's XformOperationType in the high 4
/// bits: scale 0, translate 1, rotate about an axis 2, matrix 3, rotate X/Y/Z 4-6; angles in
/// degrees) with their channels taken in order from @a vals; each operation's matrix premultiplies
/// the product so far, so a point is transformed by the last operation first.
/// @return an empty string, or the rule broken (an unknown type, too few values, a non-finite
/// result), for the reader to put after the file and property.
std::string composeAbcOps(const std::vector<std::uint8_t>& ops, const std::vector<double>& vals, Matrix& out);

/// @brief The matrix of one USD xformOp: @a type is the name's second part (`xformOp:TYPE[:suffix]`:
/// translate, scale, rotateX/Y/Z, rotateXYZ and its five other orders, orient, transform) and
/// @a v its value flattened (3, 3, 1, 3, 4 as (w, x, y, z), 16 numbers; angles in degrees). A
/// `rotateABC` value holds the angles about X, Y and Z in that order, applied A first.
/// @return an empty string, or the rule broken.
std::string usdOp(const std::string& type, const std::vector<double>& v, Matrix& out);

/// @brief @a p transformed by @a m (in double precision, with the projective divide).
Vec3f transformPoint(const Matrix& m, const Vec3f& p);

} // namespace xform
} // namespace vdbhair
