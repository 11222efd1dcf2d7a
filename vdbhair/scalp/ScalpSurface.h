/// @file ScalpSurface.h
/// @brief Scalps as OpenVDB narrow-band level sets (docs/scalps.md, grid `surface`): a FloatGrid of
/// signed distance in world units, negative inside the head, class `level set`, named `surface`,
/// with `creator` and `vdbhair_*` metadata saying where it came from. Three sources: a triangle
/// mesh, a sphere, and scattered oriented points (VariationalImplicit.h).
///
/// Every builder estimates the narrow band's voxel count before it allocates anything and
/// refuses (LimitError, with the estimate and the cap) above ScalpParams::maxVoxels.
#pragma once

#include <vdbhair/Types.h>
#include <vdbhair/io/MeshFile.h>
#include <vdbhair/io/PointFile.h>

#include <openvdb/Grid.h>
#include <openvdb/openvdb.h>
#include <openvdb/util/NullInterrupter.h>

#include <cstdint>
#include <string>

namespace vdbhair {

/// @brief What every scalp builder needs.
struct ScalpParams
{
    static constexpr float kMinHalfWidth = 1.f, kMaxHalfWidth = 64.f;  ///< halfWidth's range (voxels)
    static constexpr std::size_t kMinConstraints = 5;                  ///< maxConstraints's least

    double voxelSize = 0.0;  ///< world units; 0: 1/100 of the input's largest extent
    /// Half width of the narrow band in voxels. OpenVDB's default (3) is what its level-set tools
    /// and Houdini's SDF nodes expect.
    float halfWidth = 3.f;
    /// Refuse a band estimated at more voxels than this: 2^27 float voxels are about 0.7 GB with
    /// the tree's overhead, which is more than any head needs (a 1/1000 voxel head is ~3e7).
    std::uint64_t maxVoxels = std::uint64_t(1) << 27;
    /// Points: more constraint points than this are thinned to an evenly spread subset (the
    /// dense solve is cubic in their number).
    std::size_t maxConstraints = 2000;
    std::string source;  ///< stored as `vdbhair_source` (a file name, "sphere")
};

/// @brief How a mesh was made into a level set (ScalpMeshReport is filled by scalpFromMesh()).
struct ScalpMeshReport
{
    std::size_t weldedVertices = 0;  ///< vertices merged with an earlier one at the same position
    std::size_t boundaryEdges = 0;   ///< edges of one triangle after welding (0: watertight)
    std::size_t cappedLoops = 0;     ///< boundary loops closed by a fan to their centroid
    std::size_t openEdges = 0;       ///< boundary edges left open (not on a simple loop)
    std::size_t nonManifoldEdges = 0;  ///< edges of more than two triangles
};

/// @brief The voxel size used when ScalpParams::voxelSize is 0: 1/100 of the largest extent of
/// @a box (a head is then about 100 voxels across; a root spacing of 1/50 of the head is two voxels).
double defaultScalpVoxelSize(const BBox& box);

/// @brief Estimated voxels of a narrow band of half width @a halfWidth voxels around a surface of
/// area @a area (world units squared): area / h^2 * 2 * halfWidth, plus 10 % for leaf padding.
std::uint64_t estimateBandVoxels(double area, double voxelSize, double halfWidth);

/// @brief A scalp from a triangle mesh with openvdb::tools::meshToLevelSet.
///
/// Open meshes (several heads are open at the neck) have no inside, so the sign of a distance
/// to them is undefined and OpenVDB's exterior flood fill leaks through the hole. The rule:
/// vertices at the same position are welded first (exports split them along UV seams), then
/// each boundary loop (a cycle of edges that belong to one triangle, every vertex on two such
/// edges) is closed by a fan of triangles to the loop's centroid. The cap lies across the hole
/// (the neck), away from where hair grows. Boundary edges on no simple loop are left open and
/// counted; the result is then checked to enclose a volume.
/// @param report if not null, what welding and capping did
/// @throw ValueError (no triangles, a degenerate box, a bad voxel size), LimitError (the band
/// estimate over the cap), FormatError (the level set encloses nothing: the mesh is not a
/// closed surface even after capping).
openvdb::FloatGrid::Ptr scalpFromMesh(const TriangleMesh& mesh, const ScalpParams& params,
                                      ScalpMeshReport* report = nullptr,
                                      openvdb::util::NullInterrupter* interrupter = nullptr);

/// @brief The scalp in @a path: a .vdb holding a float level set named `surface` (what `vdbhair
/// scalp` writes), or a triangle mesh (.ply, .obj) made into one by scalpFromMesh() with default
/// parameters (a voxel of 1/100 of the head).
/// @throw IoError, FormatError, LookupError (no `surface` grid), TypeError (`surface` is not a
/// float level set), and as scalpFromMesh().
openvdb::FloatGrid::Ptr readScalp(const std::string& path, openvdb::util::NullInterrupter* interrupter = nullptr);

/// @brief A scalp sphere (openvdb::tools::createLevelSetSphere).
/// @param center, radius world units
/// @throw ValueError (radius not positive), LimitError.
openvdb::FloatGrid::Ptr scalpFromSphere(const Vec3d& center, double radius, const ScalpParams& params);

/// @brief A scalp through scattered points with outward normals: the variational implicit of
/// Turk and O'Brien (VariationalImplicit.h) as in Piuze et al. 2011, Sec. 4.3, sampled into the
/// narrow band. Voxels are evaluated by a front that starts at the constraint points and walks
/// the band (so only band voxels and their neighbours are evaluated); a voxel's value is
/// f / |grad f|, the first-order distance to the zero set, and the interior is sign-filled.
/// Points beyond ScalpParams::maxConstraints are thinned by farthest-point sampling.
/// @throw ValueError (fewer than 5 points, missing normals, coplanar points), LimitError,
/// FormatError (the implicit has no zero crossing near the points).
openvdb::FloatGrid::Ptr scalpFromPoints(const OrientedPoints& points, const ScalpParams& params, bool threaded = true,
                                        openvdb::util::NullInterrupter* interrupter = nullptr);

/// @brief Name the grid `surface`, class level set, and store `creator`, `vdbhair_source`,
/// `vdbhair_scalp_kind` (mesh, sphere, points), `vdbhair_voxel_size` and `vdbhair_half_width`.
void stampScalpGrid(openvdb::FloatGrid& grid, const std::string& kind, const ScalpParams& params);

} // namespace vdbhair
