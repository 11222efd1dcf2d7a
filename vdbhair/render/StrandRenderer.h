/// @file StrandRenderer.h
/// @brief Preview images of strands: orthographic front, side, top and back views and a
/// three-quarter perspective, hair shaded as lit fibres (Kajiya & Kay 1989: diffuse sin(T, L),
/// specular along the tangent), depth-correct (a z-buffer) and anti-aliased (3x3 supersampling
/// of one-subpixel lines, so dense hair shows its density).
///
/// Conventions: +y is up and the face looks towards +z (RenderParams::up and facing name other
/// axes); the front view looks along -z (the viewer stands on +z), the side view
/// along -x, the back view along +z, the top view down -y with -z at the top of the image, and
/// the three-quarter view looks at the centre from (+1, +0.6, +1). Images depend only on their
/// input: rasterization runs in horizontal bands, each drawing its segments in strand order.
#pragma once

#include <vdbhair/Parameters.h>
#include <vdbhair/io/MeshFile.h>
#include <vdbhair/render/Image.h>
#include <vdbhair/strands/StrandSet.h>

#include <openvdb/util/NullInterrupter.h>

#include <optional>
#include <string>

namespace vdbhair {

enum class View { Front, Side, Top, Back, ThreeQuarter };
/// @throw ValueError listing the views.
View viewFromName(const std::string& name);
const char* viewName(View view);

enum class ColorBy
{
    Shaded,     ///< one hair colour (or the strands' own colours), lit
    Root,       ///< the root's position on the scalp, lit
    Tangent,    ///< |T| as RGB (world axes), unlit
    Depth,      ///< distance from the viewer, colour map with a legend
    Curvature,  ///< 1 / world units, colour map with a legend (5th to 95th percentile)
    Strand,     ///< a colour per strand, lit
    Error       ///< distance to RenderParams::reference, colour map with a legend (0 to the 95th percentile)
};
/// @throw ValueError naming colorBy unless one of colorByName()'s names.
ColorBy colorByFromName(const std::string& name);
const char* colorByName(ColorBy colorBy);

struct RenderParams
{
    static constexpr int kMaxSize = 16384;  ///< most pixels of width and of height

    View view = View::ThreeQuarter;
    int width = 1024, height = 1024;  ///< pixels, 1 to kMaxSize
    ColorBy colorBy = ColorBy::Shaded;
    Vec3f hairColor{0.30f, 0.17f, 0.08f};
    Vec3f background{1.f, 1.f, 1.f};
    int supersample = 3;
    const StrandSet* guides = nullptr;     ///< drawn on top, in guideColor, twice as wide
    Vec3f guideColor{0.85f, 0.05f, 0.05f};
    std::optional<BBox> frame;             ///< the box to fit (default: the strands' own)
    std::string title;                     ///< written in the top-left corner
    /// Optional progress and Ctrl-C (Progress.h): one stage per view; InterruptedError when it
    /// stops the work.
    openvdb::util::NullInterrupter* interrupter = nullptr;
    /// The hairstyle's up axis and the direction its face looks (perpendicular unit vectors):
    /// views are named as if they were +y and +z. Without facing: +z, or -y for a ±z up (the
    /// usual z-up convention, Blender's). Yuksel's cyHair models need up (0, 0, 1), facing (0, 1, 0).
    Vec3d up{0.0, 1.0, 0.0};
    std::optional<Vec3d> facing;
    /// A head (or any occluder) drawn first, as lit grey surfaces the hair is depth-tested
    /// against, so that front views show the face framed by hair. Included in the default frame.
    const TriangleMesh* head = nullptr;
    Vec3f headColor{0.78f, 0.76f, 0.74f};
    /// ColorBy::Error's reference: each vertex is coloured by its distance to the nearest vertex
    /// of this hairstyle (the per-vertex term of the Chamfer distance, strands/Compare.h), so
    /// where two hairstyles differ shows. Required by ColorBy::Error.
    const StrandSet* reference = nullptr;
    /// The front ends draw the sheet of four views (renderSheet()) instead of one (renderStrands()).
    bool sheet = false;
};

/// @brief render's parameters declared once (vdbhair/Parameters.h): the view, the image's size, the
/// colouring, the axes (up, facing), the title and the sheet; the command's options, `--help`,
/// Python's keywords and docs/cli.md's table are made from it. The files (guides, head,
/// reference) are each front end's own.
const ParamTable<RenderParams>& renderParameters();

/// @brief The facing direction used when RenderParams::facing is not set (see there).
Vec3d defaultFacing(const Vec3d& up);

/// @brief Render one view. @throw ValueError for a zero or huge size.
Image renderStrands(const StrandSet& strands, const RenderParams& params);

/// @brief Where @a world lands in the image renderStrands(strands, params) draws: continuous pixel
/// coordinates (x right, y down; pixel (i, j) covers [i, i+1) × [j, j+1)) and, as z, the distance
/// along the view direction. @a frame is the box the render fits: params.frame if set, otherwise
/// the strands' bounding box (with the guides').
Vec3d projectToImage(const Vec3d& world, const RenderParams& params, const BBox& frame);

/// @brief The four views front, side, top and three-quarter in a 2x2 sheet of params.width ×
/// params.height, all fitted to the same box.
Image renderSheet(const StrandSet& strands, const RenderParams& params);

} // namespace vdbhair
