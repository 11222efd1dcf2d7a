/// @file ScalpRegion.h
/// @brief Where on the scalp hair grows (docs/scalps.md, grid `region`): a BoolGrid on the surface's
/// transform whose active voxels cover the part of the narrow band that carries hair.
#pragma once

#include <vdbhair/Types.h>
#include <vdbhair/io/MeshFile.h>

#include <openvdb/openvdb.h>

#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace vdbhair {

/// @brief The closest points of the zero level set to @a points, which may lie anywhere (roots
/// usually float a few voxels above the scalp, outside its narrow band): from the nearest voxel the
/// zero level set crosses (a k-d tree of them), Newton steps along the gradient (ScalpSampler).
/// @return #P world positions; @a onSurface (if not null) says which reached |phi| < 0.5 voxel.
std::vector<Vec3f> projectOntoSurface(const openvdb::FloatGrid& surface, const std::vector<Vec3f>& points,
                                      std::vector<char>* onSurface = nullptr);

/// @brief The region "where these strands have roots": each root is projected onto the surface
/// (projectOntoSurface()) and every band voxel within @a radius of the projection becomes active. Named `region`, with `creator` and `vdbhair_region_radius`, `vdbhair_source`.
/// @param roots #R world positions
/// @param radius world units; a voxel is in when its centre is within radius of a projected root
/// @param maxDistance roots farther than this from the surface (world units) are left out
/// @throw ValueError (radius not positive, no roots), LookupError (no root within maxDistance:
/// the region would be empty), LimitError (over @a maxVoxels voxels to visit).
openvdb::BoolGrid::Ptr regionFromRoots(const openvdb::FloatGrid& surface, const std::vector<Vec3f>& roots,
                                       double radius, const std::string& source = "",
                                       std::uint64_t maxVoxels = std::uint64_t(1) << 28,
                                       double maxDistance = std::numeric_limits<double>::max());

/// A float mask's default threshold (regionFromMask()): painted weights in [0, 1] cover where
/// they are more than half.
constexpr double kDefaultRegionThreshold = 0.5;

/// @brief The region from a mask grid: the surface's band voxels whose centre the mask covers. A
/// BoolGrid covers where it is true (active or not: the value is what counts; its background too);
/// a FloatGrid where its trilinear value exceeds @a threshold (a painted weight, a fog volume). The
/// mask may have any transform (sampled at world positions). Named `region`, with `creator`,
/// `vdbhair_region_kind` "mask", `vdbhair_region_threshold` and `vdbhair_source`.
/// @throw TypeError (neither a BoolGrid nor a FloatGrid), ValueError (a non-finite threshold),
/// LookupError (the mask covers no surface voxel: the region would be empty).
openvdb::BoolGrid::Ptr regionFromMask(const openvdb::FloatGrid& surface, const openvdb::GridBase& mask, double threshold = kDefaultRegionThreshold,
                                      const std::string& source = "");

/// @brief The region painted on a mesh: a value per vertex (a vertex colour channel or a named
/// property, readPlyVertexValues()), thresholded. Each band voxel of @a surface takes the
/// inverse-distance average (weights 1/d, an exact hit its vertex's value) of the values at the 4
/// mesh vertices nearest its centre, and is in the region where that exceeds @a threshold; the
/// region's rim thus lies between painted and unpainted vertices, at the mesh's resolution. Named
/// `region`, with `creator`, `vdbhair_region_kind` "vertex", `vdbhair_region_threshold` and
/// `vdbhair_source`.
/// @param values #V, one per vertex of @a mesh
/// @throw ValueError (a value count that is not the vertex count, a non-finite threshold),
/// LookupError (no voxel's value exceeds the threshold: the region would be empty).
openvdb::BoolGrid::Ptr regionFromVertexValues(const openvdb::FloatGrid& surface, const TriangleMesh& mesh, const std::vector<float>& values,
                                              double threshold = kDefaultRegionThreshold, const std::string& source = "");

/// @brief Values painted on a mesh's vertices, read anywhere: the inverse-distance average
/// (weights 1/d, an exact hit its vertex's value) of the values at the 4 vertices nearest a point.
/// regionFromVertexValues() and per-root values (RootValues.h) both use it.
class VertexValueSampler
{
public:
    /// @throw ValueError (a value count that is not the vertex count, no vertices).
    /// @param neighbors the vertices averaged, 1 to 4 (1: the nearest vertex's value, for ids)
    VertexValueSampler(const TriangleMesh& mesh, std::vector<float> values, const std::string& where, int neighbors = 4);
    ~VertexValueSampler();
    VertexValueSampler(const VertexValueSampler&) = delete;
    VertexValueSampler& operator=(const VertexValueSampler&) = delete;
    double at(const Vec3d& p) const;

private:
    std::vector<Vec3d> mVertices;
    std::vector<float> mValues;
    std::size_t mNeighbors = 4;
    struct Tree;
    std::unique_ptr<Tree> mTree;
};

/// @brief A mask grid of a .vdb file: the grid @a name; without one, the grid @a preferred if the
/// file has it, else the file's first bool or float grid that is not a level set.
/// @param option what the grid is for, in messages ("a region mask (--region-grid NAME)")
/// @throw LookupError (no such grid, or no bool or float grid: the message says how to name one),
/// TypeError (the named grid is neither bool nor float), and the reader's errors.
openvdb::GridBase::Ptr readMaskGrid(const std::string& path, const std::string& name, const std::string& preferred, const std::string& option);

} // namespace vdbhair
