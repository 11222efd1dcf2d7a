/// @file ScalpInput.h
/// @brief Scalps and their regions from files and strands, as `vdbhair scalp` / `vdbhair roots`
/// and the Python module's scalp() / roots() take them: the one place that decides what a file is
/// (a mesh, oriented points, or a strand file whose roots are the points) and the defaults of a
/// region grown from roots.
#pragma once

#include <vdbhair/Parameters.h>
#include <vdbhair/io/ReadOptions.h>
#include <vdbhair/scalp/ScalpRegion.h>
#include <vdbhair/scalp/ScalpSurface.h>
#include <vdbhair/strands/StrandSet.h>

#include <openvdb/openvdb.h>
#include <openvdb/util/NullInterrupter.h>

#include <string>
#include <vector>

namespace vdbhair {

/// @brief What `vdbhair scalp` and Python's scalp() tune: the level set's ScalpParams and the
/// region's radius and threshold, declared once in scalpParameters().
struct ScalpBuildParams
{
    ScalpParams surface;  ///< voxel size, band half width, caps (ScalpParams's defaults)
    /// A region from roots (regionFromRoots()): world units around each projected root; 0:
    /// defaultRegionRadius().
    double regionRadius = 0.0;
    /// A region from a float mask or a mesh's vertex values (regionFromMask(),
    /// regionFromVertexValues()): covered where the value exceeds this.
    double regionThreshold = kDefaultRegionThreshold;
    /// A region painted on a PLY mesh input (regionFromVertexValues()): the name of the vertex
    /// property read; empty: none.
    std::string regionVertex;
};

/// @brief scalp's parameters declared once (vdbhair/Parameters.h): the command's options and
/// `--help`, Python's scalp() keywords and docs/cli.md's table are made from it.
const ParamTable<ScalpBuildParams>& scalpParameters();

/// @brief What scalpFromFile() made and how.
struct ScalpFileReport
{
    std::string kind;            ///< "mesh" or "points"
    std::size_t triangles = 0;   ///< mesh: its triangles
    ScalpMeshReport mesh;        ///< mesh: welding and capping
    std::size_t points = 0;      ///< points: the constraint points given
    std::size_t constraints = 0; ///< points: those the solve used (ScalpParams::maxConstraints)
    ReadReport read;             ///< a strand file's reader warnings
};

/// @brief Each root of @a strands with its first segment's direction as the normal (zero for a
/// strand whose first segment has no length): constraint points for scalpFromPoints().
OrientedPoints orientedRoots(const StrandSet& strands);

/// @brief The scalp of @a path: a triangle mesh (.obj, or .ply with faces) by scalpFromMesh();
/// points with normals (.ply without faces) or a strand file's roots (orientedRoots()) by
/// scalpFromPoints(). @a params.source defaults to @a path.
/// @throw ValueError (an extension that is none of these; fewer than 5 points), and as the
/// readers and builders.
openvdb::FloatGrid::Ptr scalpFromFile(const std::string& path, const ScalpParams& params, ScalpFileReport* report = nullptr,
                                      bool threaded = true, openvdb::util::NullInterrupter* interrupter = nullptr);

/// @brief The grid `region` of a scalp .vdb (what `vdbhair scalp --region` writes), or null when
/// the file has none (or is not a .vdb).
/// @throw TypeError (`region` is not a bool grid), and as the .vdb reader.
openvdb::BoolGrid::Ptr readScalpRegion(const std::string& path);

/// @brief The radius regionFromRoots() is given when the user gives none: twice the roots' mean
/// nearest-neighbour spacing (so the discs overlap and the region has no gaps), at least two voxels.
double defaultRegionRadius(const openvdb::FloatGrid& surface, const std::vector<Vec3f>& roots);

/// @brief Roots farther from @a surface than this belong to another head: a tenth of the
/// diagonal of its active voxels' box (regionFromRoots()'s maxDistance).
double defaultRootDistance(const openvdb::FloatGrid& surface);

} // namespace vdbhair
