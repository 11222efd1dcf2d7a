/// @file FieldMapping.h
/// @brief How world positions reach a field grid's index space, for world-space grids (any
/// transform; a fast path for axis-aligned linear ones) and scalp-space grids (whose transform
/// maps index space to (u, v, w); the sphere, and the measured scalp when there is one, are in the
/// grid's metadata).
#pragma once

#include <vdbhair/field/FieldTypes.h>

#include <openvdb/Grid.h>
#include <openvdb/math/Transform.h>

#include <memory>

namespace vdbhair {

class ScalpMap;

class FieldMapping
{
public:
    /// @brief The mapping of @a grid: scalp space when its metadata says `vdbhair_space` =
    /// "scalp" (with `vdbhair_scalp_center`, `vdbhair_scalp_radius`, `vdbhair_scalp_up`; the older
    /// `vdbhair:` spellings are read too), else world. A scalp measured on a level set comes back
    /// from `vdbhair_scalp_distance` and `vdbhair_scalp_resolution` (setFieldMetadata()).
    /// @throw FormatError if scalp metadata is missing or invalid.
    static FieldMapping fromGrid(const openvdb::GridBase& grid);

    /// @brief World space with the transform @a xform.
    explicit FieldMapping(openvdb::math::Transform::ConstPtr xform);
    /// @brief Scalp space: (u, v, w) mapped by @a xform.
    FieldMapping(openvdb::math::Transform::ConstPtr xform, const ScalpSphere& scalp);
    /// @brief Scalp space over a measured scalp (ScalpMap.h: w is the height above it); null
    /// @a surface is the sphere of the other constructor.
    FieldMapping(openvdb::math::Transform::ConstPtr xform, std::shared_ptr<const ScalpMap> surface);

    FieldSpace space() const { return mSpace; }
    const ScalpSphere& scalp() const { return mScalp; }
    /// The measured scalp of a scalp-space mapping, or null (the sphere).
    const std::shared_ptr<const ScalpMap>& scalpSurface() const { return mSurface; }
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
    std::shared_ptr<const ScalpMap> mSurface;
    openvdb::math::Transform::ConstPtr mXform;
    bool mDiagonal = false;
    openvdb::Vec3d mOffset{0.0}, mInvScale{1.0};
};

/// @brief Write the self-describing metadata (docs/fields.md) on a field grid: `creator`,
/// `vdbhair_voxel_size`, `vdbhair_iterations`, `vdbhair_space`, `vdbhair_level`, `vdbhair_levels`,
/// `vdbhair_strand_count`, and for scalp-space grids the sphere and, with @a surface, the measured
/// scalp: `vdbhair_scalp_resolution` (int) and `vdbhair_scalp_distance`, its d table as text (the
/// resolution² values, row v then column u, in units of the radius, separated by spaces, each
/// printed with the 9 digits that give its float back exactly: `numpy.array(s.split(), 'f4')`).
void setFieldMetadata(openvdb::GridBase& grid, double voxelSize, int iterations, FieldSpace space,
                      const ScalpSphere& scalp, int level, int levels, std::size_t strandCount,
                      const ScalpMap* surface = nullptr);

} // namespace vdbhair
