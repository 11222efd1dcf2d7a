/// @file SliceRenderer.h
/// @brief An image of one axis-aligned slice through a grid (`vdbhair inspect --slice`).
///
/// The slice is the plane axis = world coordinate, sampled per pixel at the nearest voxel (what
/// is stored, not a smoothed version of it); inactive voxels are light grey. Vector grids are
/// coloured by direction: `Rgb` maps |x|, |y|, |z| of the unit vector to red, green and blue;
/// `Hsv` maps the in-plane angle to hue (so opposite directions differ, which RGB cannot show),
/// the in-plane share of the vector to saturation; both scale brightness by the length over the
/// grid's 99th-percentile length. Scalar grids go through the viridis colour map over the slice's
/// value range, with a colour bar and the range written beside it. Streamlines (`streamlines`
/// > 0) follow the vector field projected into the plane (midpoint steps of half a voxel,
/// trilinear samples in the slice plane), both ways from seeds spread evenly over the slice's
/// active voxels, drawn in white over a dark edge.
///
/// Orientation matches `vdbhair render`'s views: z slices are seen from the front (x right,
/// y up), x slices from the side (-z right, y up), y slices from the top (x right, -z up).
#pragma once

#include <vdbhair/Parameters.h>
#include <vdbhair/io/VdbInspect.h>
#include <vdbhair/render/Image.h>

#include <string>
#include <vector>

namespace vdbhair {

enum class SliceColor { Rgb, Hsv };

struct SliceParams
{
    static constexpr int kMinWidth = 16, kMaxWidth = 16384;  ///< pixels
    static constexpr int kMaxStreamlines = 100000;

    int axis = 2;               ///< 0: x, 1: y, 2: z
    double world = 0.0;         ///< the plane's world coordinate along @a axis
    int width = 1024;           ///< of the plot, kMinWidth to kMaxWidth (height follows the grid's aspect)
    SliceColor color = SliceColor::Rgb;
    int streamlines = 0;        ///< 0 to kMaxStreamlines
};

/// @brief The slice's parameters declared once (vdbhair/Parameters.h): `hsv` (the colouring,
/// SliceColor::Hsv when on), `streamlines` and `width`, with their ranges; `inspect`'s options and
/// Python's `inspect()` keywords are made from it. The plane itself (axis, world) is given as
/// text, AXIS=WORLD (parseSlice()).
const ParamTable<SliceParams>& sliceParameters();

struct SliceResult
{
    Image image;
    int indexPlane = 0;         ///< the voxel layer shown
    std::size_t activeVoxels = 0;  ///< in that layer
    double lo = 0.0, hi = 0.0;  ///< scalars: the value range shown; vectors: the length range
    int streamlinesDrawn = 0;
};

/// @brief Render the slice of grid @a gridName of the .vdb file @a path.
/// @throw LookupError (no such grid), ValueError (a point grid, an unsupported value type, an
/// empty grid, a non-linear transform, a slice outside the grid's active voxels, a parameter out of
/// its declared range, named as sliceParameters() names it), IoError, FormatError.
SliceResult renderSlice(const std::string& path, const std::string& gridName, const SliceParams& params);

/// @brief Parse "x=1.5" (axis x, y or z, then a world coordinate).
/// @throw ParamError<ValueError> naming the rule.
void parseSlice(const std::string& text, int& axis, double& world);

/// @brief What `inspect` takes besides the file and the image's path: the grid it describes (and
/// slices), the plane, and how the slice is drawn.
struct InspectParams
{
    std::string grid;   ///< only this grid, and the one sliced; empty: every grid (chooseSliceGrid())
    std::string slice;  ///< the plane, AXIS=WORLD (parseSlice()); empty: no slice
    SliceParams draw;   ///< its axis and world are set from @c slice (inspectSlice())
};

/// @brief inspect's parameters declared once: `grid`, `slice` and sliceParameters()'s; `inspect`'s
/// options, Python's `inspect()` keywords and docs/cli.md are made from it.
const ParamTable<InspectParams>& inspectParameters();

/// @brief The slice @a p asks for, its plane parsed, checked against the image's path @a output
/// (the command line's -o, Python's output=; empty: none): a slice needs an image in a format
/// OpenImageIO writes, an image needs a slice, and `hsv` and `streamlines` draw on a slice.
/// @throw ParamError<ValueError> naming the parameters (after "@a where: " when @a where is not
/// empty), and parseSlice()'s.
SliceParams inspectSlice(const InspectParams& p, const std::string& output, const std::string& where);

/// @brief The grid a slice of the file @a path shows: @a grid when it is given, else 'tangent'
/// when @a reports has it, else the first voxel grid of @a reports (inspectVdbFile()'s, in file
/// order).
/// @throw ValueError when @a grid is empty and @a reports holds no voxel grid (only points).
std::string chooseSliceGrid(const std::vector<GridReport>& reports, const std::string& grid, const std::string& path);

} // namespace vdbhair
