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
/// arrays are written with "vertex" interpolation unless every value is the same, and where the
/// set has none its defaults (the cyHair header's) are written as one "constant" value (widths:
/// UsdWriteOptions::width, else the declared default, else automaticUsdWidth()); the defaults are also written exactly as
/// custom attributes `vdbhair_default_*`, so `.hair -> .usda -> .hair` keeps both.
/// Floats are written in the shortest form that reads back exactly.
///
/// Reading accepts every `def BasisCurves` prim of the file (concatenated in file order), nested
/// in any `def` prims; `uniform`, `constant`, `vertex` and `varying` interpolation; comments,
/// prim and property metadata, and other prims and properties (ignored). Points are read into the
/// stage's space: the `xformOp`s that a prim and each of its parents list in `xformOpOrder` are
/// composed as `UsdGeomXformable` does (Xform.h; widths scale with the transform). Cubic curves
/// (bezier, bspline, catmullRom; nonperiodic, periodic, pinned) are evaluated to polylines by
/// FreeFormCurve.h (ReadOptions::curveSamples), their vertex and varying primvars interpolated
/// along them; USD's fallback type, cubic Bezier, applies when `type` is not authored unless the
/// counts cannot be Bezier curves (read as linear, with a warning). An attribute with time
/// samples is read at its first (a warning says so). `upAxis` and `metersPerUnit`
/// are carried in StrandSet::upAxis and StrandSet::metersPerUnit (USD's fallbacks, Y and 0.01,
/// when the stage has none), never applied (no rotation or scaling; a "Z" up axis is reported in a
/// warning: render such hair with `--up z`), and written again by writeUsda() unless told
/// otherwise, so USD to USD keeps them. A `.usd` file holding USD text reads the same; a binary
/// (crate) `.usd` is refused with UnsupportedError.
#pragma once

#include <vdbhair/io/ReadOptions.h>
#include <vdbhair/strands/StrandSet.h>

#include <string>

namespace vdbhair {

struct UsdWriteOptions
{
    /// The stage's `upAxis`: "Y" (vdbhair's convention: +Y up, face towards +Z) or "Z"; empty: the
    /// strands' declared axis (StrandSet::upAxis), else "Y". Coordinates are written unchanged;
    /// this only declares how to read them.
    std::string upAxis;
    /// The stage's `metersPerUnit`; 0: the strands' own (StrandSet::metersPerUnit, read from a
    /// USD stage), else 0.01 (USD's own fallback, centimetres).
    double metersPerUnit = 0.0;
    /// `widths` (world units) of curves without thickness; 0: the file's declared default
    /// thickness if it differs from 1, else automatic (automaticUsdWidth()).
    float width = 0.f;
};

/// @brief The width automaticUsdWidth() gives, as a share of the bounding box's diagonal.
///
/// Measured on the shared hairstyles in their declared units (docs/formats.md): 0.37 mm (CT2Hair's
/// Bangs and Curly, mm), 0.58-0.69 mm (HairNet's, metres), 0.94-1.97 mm (TressFX's Ruby and
/// ponytail, cm), 1.1 mm (Ratboy, metres), 1.22 mm (Yuksel's straight, cm): thin lines, 5 to 25
/// real hairs wide (0.05-0.1 mm), the same for 5 guides or 10,000 strands, where the constant 1
/// drew hair in metres a metre wide (five times the head) and hair in cm 10 mm wide.
constexpr float kAutomaticWidthPerDiagonal = 1e-3f;

/// @brief The `widths` written for curves without thickness when no width is given: the bounding
/// box's diagonal times kAutomaticWidthPerDiagonal (1 for a set of one point).
float automaticUsdWidth(const StrandSet& strands);

/// @throw IoError, FormatError naming the file, the line and the rule (no BasisCurves prim,
/// counts that do not add up to the points, an array of the wrong length, a syntax error).
StrandSet readUsda(const std::string& path, const ReadOptions& opts = {}, ReadReport* report = nullptr);

/// @brief Write the strands as one linear BasisCurves prim named "hair" (the default prim).
/// @throw ValueError (empty set, an up axis other than Y or Z, metersPerUnit not positive), IoError.
void writeUsda(const std::string& path, const StrandSet& strands, const UsdWriteOptions& opts = {});

} // namespace vdbhair
