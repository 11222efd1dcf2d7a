/// @file RootValues.h
/// @brief One value per root, from wherever an artist keeps it: a number, a text file of one
/// value per root, a mask grid in a .vdb (painted in Houdini, or `vdbhair scalp --region-mask`'s
/// kind), or a property painted on the head mesh's vertices (a PLY weight or colour channel).
/// `interpolate --density` and `--length` read theirs this way (GroomControls.h).
#pragma once

#include <vdbhair/Types.h>

#include <cstdint>
#include <string>
#include <vector>

namespace vdbhair {

/// @brief The value of @a spec at each of @a roots:
/// - a number ("0.5"): that value at every root;
/// - `FILE.vdb` or `FILE.vdb:GRID`: a float grid's trilinear value at each root (world space;
///   a bool grid gives 1 where true, 0 elsewhere); without GRID, the grid named @a preferred,
///   else the file's first bool or float grid that is not a level set;
/// - `MESH.ply:PROPERTY`: a vertex property of a mesh (a painted weight, or `red`, `green`, `blue`
///   as value / 255), the inverse-distance average of the 4 vertices nearest each root
///   (VertexValueSampler);
/// - any other file: one number per root, in the roots' order (readValueList()).
/// @param option names the option in messages ("--density")
/// @throw ValueError (a value count that is not the root count, a non-finite value), LookupError,
/// TypeError, FormatError, IoError from the readers, each naming the file.
/// @param nearest sample without blending (ids): a float grid's value in the voxel holding the
/// root, a mesh property's value at the nearest vertex
std::vector<float> readRootValues(const std::string& spec, const std::vector<Vec3d>& roots, const std::string& option, const std::string& preferred,
                                  bool nearest = false);

/// @brief Integer ids (groups) at @a points from @a spec: a text file of one id per point
/// (readIdList()); `MASK.vdb[:GRID]` (the value of the voxel holding each point; default grid
/// `groups`); `MESH.ply:PROPERTY` (the nearest vertex's value); or `MESH.ply:islands` /
/// `MESH.obj:islands`, the mesh's connected pieces (vertices at one position are one vertex),
/// numbered from 0 in the order of their first triangle, each point taking the piece of its
/// nearest vertex: Blender's "part by mesh islands" (a scalp cut along its partings).
/// @param what what the points are, in messages ("guides", "roots")
/// @throw ValueError (a value that is not an integer, a count that is not the point count), and
/// the readers' errors, each naming the file.
std::vector<std::int32_t> readRootIds(const std::string& spec, const std::vector<Vec3d>& points, const std::string& option, const std::string& what);

} // namespace vdbhair
