/// @file ObjFile.h
/// @brief Wavefront OBJ polylines (`.obj`): `v x y z` vertices and `l i j k ...` polyline
/// elements, as Houdini and Blender export curves.
///
/// Reading: indices are 1-based, negative indices count back from the latest vertex, `i/t`
/// forms take the vertex index. Each `l` element is a strand; an `l` element that starts at the
/// very vertex index where the previous one ended continues that strand (Blender writes curves
/// as chains of two-vertex `l` edges). `v` lines with 6 numbers (x y z r g b) give vertex colours.
/// Faces and other elements are ignored (counted in a warning); a file without `l` elements
/// is an error. Writing: one `v` line per vertex (shortest round-trip decimal floats) and one
/// `l` element per strand.
#pragma once

#include <vdbhair/io/ReadOptions.h>
#include <vdbhair/strands/StrandSet.h>

#include <string>

namespace vdbhair {

/// @throw IoError, FormatError (bad numbers, index out of range or zero, no polylines).
StrandSet readObj(const std::string& path, const ReadOptions& opts = {}, ReadReport* report = nullptr);

/// @brief Write positions (and colours when present) as polylines.
void writeObj(const std::string& path, const StrandSet& strands);

} // namespace vdbhair
