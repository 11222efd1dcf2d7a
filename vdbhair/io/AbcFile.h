/// @file AbcFile.h
/// @brief Strands as Alembic (`.abc`) `Curves`, in the Ogawa container (Ogawa.h): the form grooms
/// travel in between Houdini, Maya/XGen, Blender and Unreal's groom importer.
///
/// No Alembic library is packaged for Debian, so vdbhair writes and reads the format itself, from
/// the published layout of the Ogawa container, AbcCoreOgawa's object, property and time-sampling
/// encoding and the AbcGeom `Curves` schema (checked against the reference library, see
/// docs/development.md). What is written, one static sample in the default time sampling:
///
/// ```
/// /                        archive: _ai_AlembicVersion, _ai_Application = "vdbhair <version>"
///   hair                   schema=AbcGeom_Curve_v2;schemaBaseType=AbcGeom_GeomBase_v1;
///                          schemaObjTitle=AbcGeom_Curve_v2:.geom
///     .geom                compound, schema=AbcGeom_Curve_v2;schemaBaseType=AbcGeom_GeomBase_v1
///       .selfBnds          float64[6] scalar, interpretation=box
///       P                  float32[3] array, geoScope=vtx;interpretation=point
///       nVertices          int32 array, one count per curve
///       curveBasisAndType  uint8[4] scalar: kLinear, kNonPeriodic, kNoBasis, kNoBasis
///       uv                 float32[2] array, arrayExtent=1;geoScope=uni;interpretation=vector;
///                          isGeomParam=true;podExtent=2;podName=float32_t
///                          (the root UV, one per curve, when the set has it)
///       width              float32 array, arrayExtent=1;geoScope=vtx (per vertex) or geoScope=con
///                          (one value: the default thickness);isGeomParam=true;podExtent=1;
///                          podName=float32_t
///       .arbGeomParams     compound (geometry parameters as AbcGeom writes them):
///         groom_version_major, groom_version_minor   int16, geoScope=con: 1 and 5
///         groom_guide      int32, geoScope=con: 1 for an object of guides (AbcCurves::guides), else 0
///         Cd               float32[3] array, geoScope=vtx;interpretation=rgb (the colours, if any)
///         groom_root_uv    float32[2] array, geoScope=uni (the root UVs, again: Unreal's name)
///         groom_id         int32 array, geoScope=uni (StrandSet::strandId, if any)
///         groom_width      float32 array, geoScope=vtx (the thickness, again: Unreal's name)
///         groom_group_id   int32 array, geoScope=uni (AbcCurves::groupId, if any)
///         groom_closest_guides  int32[3] array, geoScope=uni  } the guides (their groom_id) and
///         groom_guide_weights   float32[3] array, geoScope=uni } weights of each curve, if any
/// ```
///
/// Several objects are siblings under the archive's top object, in the order given (`interpolate`
/// writes its guides as `/guides` and the new hair as `/hair`). The groom_* attributes follow
/// Unreal's "Alembic for Grooms" specification (schema version 1.5). Widths are vdbhair's thickness
/// (a diameter in world units, as Alembic's and USD's widths).
///
/// Reading takes every object whose schema is `AbcGeom_Curve_v*`, in hierarchy order (depth
/// first, children in file order), concatenated. Linear curves are read as they are (periodic ones
/// closed by repeating their first point); cubic Bezier, B-spline and Catmull-Rom curves are
/// evaluated into polylines by FreeFormCurve.h (ReadOptions::curveSamples points per curve, or its
/// adaptive 1 % rule when 0), with per-vertex widths interpolated along the polyline. Widths of
/// any scope (constant, uniform, varying, vertex), indexed or not, and a uniform or indexed root
/// `uv` are read; from `.arbGeomParams`, `Cd` (per vertex, interpolated along cubic curves, per
/// curve, or one colour), `groom_id`, and `groom_width` and `groom_root_uv` where `width` and `uv`
/// are absent. Animated properties are read at their first sample, with a warning; the
/// transforms of parent Xform objects are applied to the points (their `.ops` and `.vals`
/// composed as AbcGeom's XformSample::getMatrix does, `.inherits` honoured; widths scale with
/// them); NURBS (`kVariableOrder`) curves other
/// than order 2, Hermite and power bases are refused (UnsupportedError). Unreal's `groom_guide`
/// (int8, int16 or int32; per object or per curve) marks simulation guides: when an archive holds
/// both guides and other curves, the other curves (the hair) are read, with a warning naming the
/// guides left out; an archive of guides only is read whole.
///
/// Every offset and count in the file is checked against the file size before it is used, and
/// the object tree is walked with an explicit stack (no recursion on the file's depth); a group
/// reached twice (a cycle) is an error.
#pragma once

#include <vdbhair/io/ReadOptions.h>
#include <vdbhair/strands/StrandSet.h>

#include <cstdint>
#include <string>
#include <vector>

namespace vdbhair {

/// @brief Read the strands of every Curves object in the Alembic archive @a path.
/// @throw IoError, FormatError naming the file, the byte offset, the value and the rule;
/// UnsupportedError (an HDF5 archive, NURBS, Hermite or power curves).
StrandSet readAbc(const std::string& path, const ReadOptions& opts = {}, ReadReport* report = nullptr);

/// One Curves object to write: strands, and Unreal's per-curve groom attributes beside them.
struct AbcCurves
{
    std::string name = "hair";
    const StrandSet* strands = nullptr;
    bool guides = false;                      ///< simulation guides (groom_guide = 1), not rendered hair
    std::vector<std::int32_t> groupId;        ///< #S or empty: groom_group_id
    std::vector<std::int32_t> closestGuides;  ///< 3 #S or empty: groom_closest_guides, the groom_id of guide curves
    std::vector<float> guideWeights;          ///< 3 #S (with closestGuides) or empty: groom_guide_weights
};

/// @brief Write the strands as one linear Curves object `/hair` (layout above), atomically.
/// @throw ValueError (empty set), IoError.
void writeAbc(const std::string& path, const StrandSet& strands);

/// @brief Write @a objects as sibling Curves objects, in order, atomically.
/// @throw ValueError (no objects, an empty set, a name that is empty, has '/' or repeats, groom
/// attributes of the wrong size), IoError.
void writeAbc(const std::string& path, const std::vector<AbcCurves>& objects);

} // namespace vdbhair
