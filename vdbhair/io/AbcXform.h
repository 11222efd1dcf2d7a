/// @file AbcXform.h
/// @brief Alembic `Xform` operations as one 4x4 matrix, as AbcGeom's `XformSample::getMatrix`
/// composes them (AbcFile.h applies the parents' matrices to the points it reads).
#pragma once

#include <vdbhair/Types.h>

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace vdbhair {
namespace abc {

/// A 4x4 matrix in Imath's convention (Alembic's): row vectors, p' = p M, translation in row 3.
using Matrix = std::array<double, 16>;
constexpr Matrix kIdentity{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};

/// @brief The product a b (apply a, then b, to row vectors).
Matrix multiply(const Matrix& a, const Matrix& b);

/// @brief The matrix of @a ops (one byte each, AbcGeom's XformOperationType in the high 4 bits:
/// scale 0, translate 1, rotate about an axis 2, matrix 3, rotate X/Y/Z 4-6; angles in degrees)
/// with their channels taken in order from @a vals; each operation's matrix premultiplies the
/// product so far, so a point is transformed by the last operation first.
/// @return an empty string, or the rule broken (an unknown type, too few values, a non-finite
/// result), for the reader to put after the file and property.
std::string composeXformOps(const std::vector<std::uint8_t>& ops, const std::vector<double>& vals, Matrix& out);

/// @brief @a p transformed by @a m (in double precision, with the projective divide).
Vec3f transformPoint(const Matrix& m, const Vec3f& p);

} // namespace abc
} // namespace vdbhair
