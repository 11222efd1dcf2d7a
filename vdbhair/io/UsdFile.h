/// @file UsdFile.h
/// @brief Strands as USD text (`.usda`): one `UsdGeomBasisCurves` prim of linear curves, the form
/// Houdini's Solaris, Blender and Unreal's groom pipelines exchange.
///
/// No C++ USD library is packaged for Debian, so vdbhair writes and reads the text form itself
/// (the crate-based binary `.usdc` needs Pixar's library or a reimplementation of its compressed
/// layout; it is not written). What is written:
///
/// ```
/// #usda 1.0
/// (
///     defaultPrim = "hair"
///     metersPerUnit = 0.01
///     upAxis = "Y"
/// )
/// def BasisCurves "hair"
/// {
///     uniform token type = "linear"
///     uniform token wrap = "nonperiodic"
///     int[] curveVertexCounts = [17, 2, 33]
///     point3f[] points = [(x, y, z), ...]
///     float[] widths = [...] (interpolation = "vertex")      // or one value, "constant"
///     color3f[] primvars:displayColor = [...] (interpolation = "vertex")  // or "constant"
///     float[] primvars:displayOpacity = [...] (interpolation = "vertex")  // 1 - transparency
///     custom float vdbhair_default_thickness = 1         // the defaults, exactly
///     custom float vdbhair_default_transparency = 0
///     custom color3f vdbhair_default_color = (0.5, 0.5, 0.5)
///     float3[] extent = [(min), (max)]
/// }
/// ```
///
/// Widths are vdbhair's thickness (a diameter in world units, as USD's `widths`); per-vertex
/// arrays are written with "vertex" interpolation, and where the set has none its defaults (the
/// cyHair header's) are written as one "constant" value; the defaults are also written exactly as
/// custom attributes `vdbhair_default_*`, so `.hair -> .usda -> .hair` keeps both.
/// Floats are written in the shortest form that reads back exactly.
///
/// Reading accepts every `def BasisCurves` prim of the file (concatenated in file order), nested
/// in any `def` prims; `uniform`, `constant`, `vertex` and `varying` interpolation; comments,
/// prim and property metadata, and other prims and properties (ignored). Transforms
/// (`xformOp`s) are not applied and time samples are not read (a warning says so). A `cubic`
/// curve's control points are read as a polyline, with a warning. `upAxis` and `metersPerUnit`
/// are kept as they are (no rotation or scaling; a "Z" up axis is reported in a warning:
/// render such hair with `--up z`).
#pragma once

#include <vdbhair/io/ReadOptions.h>
#include <vdbhair/strands/StrandSet.h>

#include <string>

namespace vdbhair {

struct UsdWriteOptions
{
    /// The stage's `upAxis`: "Y" (vdbhair's convention: +Y up, face towards +Z) or "Z".
    /// Coordinates are written unchanged; this only declares how to read them.
    std::string upAxis = "Y";
    /// The stage's `metersPerUnit` (USD's own fallback is 0.01, centimetres).
    double metersPerUnit = 0.01;
};

/// @throw IoError, FormatError naming the file, the line and the rule (no BasisCurves prim,
/// counts that do not add up to the points, an array of the wrong length, a syntax error).
StrandSet readUsda(const std::string& path, const ReadOptions& opts = {}, ReadReport* report = nullptr);

/// @brief Write the strands as one linear BasisCurves prim named "hair" (the default prim).
/// @throw ValueError (empty set, an up axis other than Y or Z, metersPerUnit not positive), IoError.
void writeUsda(const std::string& path, const StrandSet& strands, const UsdWriteOptions& opts = {});

} // namespace vdbhair
