/// @file MeshFile.h
/// @brief Triangle meshes (heads and scalps, `../shared/data/scalp/`) from PLY and OBJ, for
/// drawing a head behind the hair (`vdbhair render --head`).
///
/// PLY: ascii or binary little-endian, a `vertex` element with x, y, z and a `face` element with
/// a `vertex_indices` (or `vertex_index`) list. OBJ: `v` and `f` lines (`i`, `i/t`, `i//n`,
/// `i/t/n`; negative indices count back). Polygons are split into triangle fans. Readers check
/// indices against the vertex count and counts against the file's size before allocating.
#pragma once

#include <vdbhair/Types.h>

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace vdbhair {

struct TriangleMesh
{
    std::vector<Vec3f> vertices;
    std::vector<std::array<std::uint32_t, 3>> triangles;
};

/// @brief Read a triangle mesh, the format by extension (.ply, .obj).
/// @throw FormatError, UnsupportedError, IoError naming the file, the place and the rule.
TriangleMesh readTriangleMesh(const std::string& path);

/// @brief The PLY and OBJ readers behind readTriangleMesh().
TriangleMesh readPlyMesh(const std::string& path);
TriangleMesh readObjMesh(const std::string& path);

/// @brief The bounding box of the mesh's vertices.
BBox meshBBox(const TriangleMesh& mesh);

} // namespace vdbhair
