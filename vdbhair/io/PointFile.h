/// @file PointFile.h
/// @brief Oriented points in PLY: scalp constraint points (`vdbhair scalp POINTS.ply`) and roots
/// (`vdbhair roots -o roots.ply`). An element `vertex` with float x, y, z, optional nx, ny, nz
/// (the outward normal) and optional tx, ty, tz (a tangent; roots carry one). ASCII and binary
/// little-endian are read; writing is binary little-endian, which Houdini, Blender and MeshLab
/// open as a point cloud.
#pragma once

#include <vdbhair/Types.h>

#include <string>
#include <vector>

namespace vdbhair {

/// @brief Points with optional normals and tangents (each empty or of the points' size).
struct OrientedPoints
{
    std::vector<Vec3f> positions;  ///< #P world positions
    std::vector<Vec3f> normals;    ///< #P unit outward normals, or empty
    std::vector<Vec3f> tangents;   ///< #P unit tangents, or empty

    std::size_t size() const { return positions.size(); }
};

/// @brief Read the `vertex` element of a PLY file (other elements are skipped).
/// @throw IoError, FormatError (no vertex element, no x y z, a non-finite value),
/// UnsupportedError (big-endian).
OrientedPoints readPlyPoints(const std::string& path);

/// @brief The number of items of element @a element in the PLY header of @a path (0 if absent).
/// @throw IoError, FormatError.
std::uint64_t plyElementCount(const std::string& path, const std::string& element);

/// @brief One scalar property of the `vertex` element of a PLY file, one value per vertex: a
/// painted mask such as a vertex colour channel (`red`, `green`, `blue`, `alpha`) or any named
/// property (`quality`, `hair`, ...). Integer colour channels of type uchar are scaled to [0, 1]
/// (value / 255, the PLY colour convention); every other property is returned as stored.
/// @throw IoError, FormatError (no vertex element, no such scalar property: the message lists the
/// vertex element's properties; a non-finite value), UnsupportedError (big-endian).
std::vector<float> readPlyVertexValues(const std::string& path, const std::string& property);

/// @brief Write binary little-endian PLY with x y z, and nx ny nz / tx ty tz when present,
/// atomically (FileUtil.h).
/// @throw ValueError (normals or tangents of the wrong size), IoError.
void writePlyPoints(const std::string& path, const OrientedPoints& points);

} // namespace vdbhair
