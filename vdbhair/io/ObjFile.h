/// @file ObjFile.h
/// @brief Wavefront OBJ lines (`.obj`): `v x y z` vertices and `l` line elements, as Houdini
/// and Blender export curves and loose edges.
///
/// **Writing.** One `v` line per vertex (shortest round-trip decimal floats, `x y z r g b` when
/// the set has colours), in strand order, root first. By default each segment is its own
/// two-vertex `l i j` element, chained per strand (`l 1 2`, `l 2 3`, ...): Blender 3.4's default
/// OBJ importer (`wm.obj_import`) keeps only the first segment of a longer `l` element, so this
/// is the only form it reads completely (it imports loose edges; tests/apps/check_blender_obj.py
/// counts them). ObjLineStyle::Polylines writes one `l` element per strand instead, which
/// Houdini and most other tools read as one curve each.
///
/// **Reading.** Every `l` element contributes its consecutive pairs as edges; strands are
/// rebuilt from the edges by connectivity, so edges may come in any order and any direction
/// (Blender writes them unchained). Each connected chain is one strand, rooted at its end with
/// the lower vertex index (or, with ReadOptions::objRootNear, at the end nearest that point);
/// strands are ordered by the index of that lower end, which reproduces the order of every file
/// vdbhair writes. A vertex joined to three or more others (a branch) and a closed loop are
/// errors naming the vertex (1-based, as in the file) and the lines involved. A one-vertex `l`
/// element on a vertex no edge uses is a one-vertex strand (dropped or rejected like any short
/// strand). Indices are 1-based; negative ones count back from the latest vertex; `i/t` forms
/// take the vertex index. The chaining is EdgeChains.h's, shared with the PLY reader.
///
/// Free-form curves (Maya, ZBrush, character creators, Blender's "Curves as NURBS"): `cstype [rat]
/// bspline|bezier|cardinal`, `deg N` (3 when absent), `curv u0 u1 i1 i2 ...` (indices as for `l`,
/// negative ones relative), `parm u ...` (the knot vector of a bspline, uniform and clamped when
/// absent; a bezier's or cardinal's segment ends) and `end`; a rational curve takes each control
/// point's weight from `v x y z w`. Each curve becomes one strand, root at its first control
/// point, evaluated at ReadOptions::curveSamples points or by FreeFormCurve.h's adaptive rule
/// (within 1 % of the curve's length); curve strands follow the line strands, in file order.
/// `cstype taylor` and `bmatrix` are refused (UnsupportedError); `curv2` and `surf` elements are
/// skipped with a warning. Lines ending in `\` continue on the next line.
///
/// Faces and other elements are ignored (counted in a warning); a file without `l` elements and
/// curves is an error.
///
/// **Axes.** OBJ has no up axis. Blender's OBJ importer (default "Up: Y, Forward: -Z") turns the
/// file's +Y into Blender's +Z (x, y, z) -> (x, -z, y), and its exporter turns it back with the
/// same defaults, so a vdbhair (+Y up) file arrives upright in Blender and round-trips unchanged.
#pragma once

#include <vdbhair/io/ReadOptions.h>
#include <vdbhair/strands/StrandSet.h>

#include <string>

namespace vdbhair {

/// How writeObj() writes each strand's line elements.
enum class ObjLineStyle
{
    Edges,      ///< a chain of two-vertex `l` elements (Blender reads every segment; the default)
    Polylines,  ///< one `l` element per strand (Houdini; Blender keeps only its first segment)
};

/// @brief Parse "edges" or "polylines". @throw ValueError otherwise.
ObjLineStyle objLineStyleFromName(const std::string& name);

/// @throw IoError, FormatError (bad numbers, index out of range or zero, no polylines, a
/// branching vertex, a closed loop, a curve that breaks a rule of its basis), UnsupportedError
/// (taylor and basis-matrix curves).
StrandSet readObj(const std::string& path, const ReadOptions& opts = {}, ReadReport* report = nullptr);

/// @brief The words writeObj()'s header comment uses for StrandSet::upAxis: "+Y up", "+Z up
/// (import into Blender with Up: Z)", or that the source declared none (0).
std::string objUpAxisWords(char upAxis);

/// @brief Write positions (and colours when present) as line elements.
void writeObj(const std::string& path, const StrandSet& strands, ObjLineStyle style = ObjLineStyle::Edges);

} // namespace vdbhair
