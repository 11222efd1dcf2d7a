/// @file SphereMesh.h
/// @brief A triangle mesh of a sphere, for drawing a scene's head (`"head": {"sphere": ...}`, see
/// Scene.h) behind its hair with RenderParams::head.
#pragma once

#include <vdbhair/io/MeshFile.h>

namespace vdbhair {

/// @brief A UV sphere: @a rings bands of latitude between the poles of the y axis and @a segments
/// of longitude; 2 · segments · (rings − 1) triangles, wound counter-clockwise seen from outside.
/// The defaults (24 × 48: 2,208 triangles, edges of 1/15 of the radius) look round in a 1024-pixel
/// render with the renderer's flat shading and cost nothing next to the hair.
/// @param center, radius world units
/// @throw ValueError for a radius that is not positive and finite, or fewer than 2 rings or
/// 3 segments.
TriangleMesh makeSphereMesh(const Vec3d& center, double radius, int rings = 24, int segments = 48);

} // namespace vdbhair
