/// @file FieldMapping.h
/// @brief How world positions reach a field grid's index space, for world-space grids (any
/// transform; a fast path for axis-aligned linear ones) and scalp-space grids (whose transform
/// maps index space to (u, v, w); the sphere is in the grid's metadata).
#pragma once

#include <vdbhair/field/FieldTypes.h>

#include <openvdb/Grid.h>
#include <openvdb/math/Transform.h>

namespace vdbhair {

class FieldMapping
{
public:
    /// @brief The mapping of @a grid: scalp space when its metadata says `vdbhair_space` =
    /// "scalp" (with `vdbhair_scalp_center`, `vdbhair_scalp_radius`, `vdbhair_scalp_up`; the older
    /// `vdbhair:` spellings are read too), else world.
    /// @throw FormatError if scalp metadata is missing or invalid.
    static FieldMapping fromGrid(const openvdb::GridBase& grid);

    /// @brief World space with the transform @a xform.
    explicit FieldMapping(openvdb::math::Transform::ConstPtr xform);
    /// @brief Scalp space: (u, v, w) mapped by @a xform.
    FieldMapping(openvdb::math::Transform::ConstPtr xform, const ScalpSphere& scalp);

    FieldSpace space() const { return mSpace; }
    const ScalpSphere& scalp() const { return mScalp; }
    const openvdb::math::Transform& transform() const { return *mXform; }

    /// @brief Index-space position of a world point.
    openvdb::Vec3d worldToIndex(const openvdb::Vec3d& world) const
    {
        const openvdb::Vec3d p = (mSpace == FieldSpace::Scalp) ? toScalp(world) : world;
        if (mDiagonal) return (p - mOffset) * mInvScale;
        return mXform->worldToIndex(p);
    }

    /// @brief Whether worldToIndex() is (world - offset()) * invScale() (world space, axis-aligned).
    bool isAxisAlignedWorld() const { return mSpace == FieldSpace::World && mDiagonal; }
    const openvdb::Vec3d& offset() const { return mOffset; }
    const openvdb::Vec3d& invScale() const { return mInvScale; }

    /// @brief The world length of one voxel near the scalp (world grids: the voxel size; scalp
    /// grids: radius times the (u, v, w) voxel size). The default tracing step is half of it.
    double worldVoxelSize() const;

private:
    openvdb::Vec3d toScalp(const openvdb::Vec3d& world) const;

    FieldSpace mSpace = FieldSpace::World;
    ScalpSphere mScalp;
    openvdb::math::Transform::ConstPtr mXform;
    bool mDiagonal = false;
    openvdb::Vec3d mOffset{0.0}, mInvScale{1.0};
};

/// @brief Write the self-describing metadata of DESIGN.md on a field grid: `creator`,
/// `vdbhair_voxel_size`, `vdbhair_iterations`, `vdbhair_space`, `vdbhair_level`, `vdbhair_levels`,
/// `vdbhair_strand_count`, and the scalp sphere for scalp-space grids.
void setFieldMetadata(openvdb::GridBase& grid, double voxelSize, int iterations, FieldSpace space,
                      const ScalpSphere& scalp, int level, int levels, std::size_t strandCount);

} // namespace vdbhair
