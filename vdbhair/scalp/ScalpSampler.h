/// @file ScalpSampler.h
/// @brief Queries on a scalp level set: the signed distance and the unit normal at any world
/// position (trilinear, of the grid and of its central-difference gradient), closest-point
/// projection onto the zero level set, and region membership.
#pragma once

#include <vdbhair/Types.h>

#include <openvdb/openvdb.h>

#include <memory>

namespace vdbhair {

class ScalpSampler
{
public:
    /// @param surface a level set (the `surface` grid); its gradient is computed once here
    /// @param region optional `region` grid on the same transform: a position belongs to it when
    /// the voxel nearest to it is active
    /// @throw TypeError if @a surface is not a level set; ValueError if the transforms differ.
    explicit ScalpSampler(openvdb::FloatGrid::ConstPtr surface, openvdb::BoolGrid::ConstPtr region = nullptr);
    ~ScalpSampler();

    /// Signed distance (world units, trilinear). @warning All queries are thread-safe.
    double distance(const Vec3d& worldPos) const;
    /// The unit outward normal (the interpolated gradient, normalized; (0,0,0) where it vanishes).
    Vec3d normal(const Vec3d& worldPos) const;
    /// @brief Newton steps p <- p - phi(p) g / |g|^2 until |phi| is below @a tolVoxels voxels or
    /// @a maxSteps steps are taken. @return the projected position.
    Vec3d project(const Vec3d& worldPos, double tolVoxels = 1e-4, int maxSteps = 12) const;
    /// Whether @a worldPos is in the region (always true without one).
    bool inRegion(const Vec3d& worldPos) const;
    bool hasRegion() const;

    /// @brief The same queries through OpenVDB value accessors (caching the last node visited):
    /// one per thread, never shared, for loops over many nearby positions. Same results.
    class Local
    {
    public:
        explicit Local(const ScalpSampler& sampler);
        double distance(const Vec3d& worldPos);
        Vec3d normal(const Vec3d& worldPos);
        Vec3d project(const Vec3d& worldPos, double tolVoxels = 1e-4, int maxSteps = 12);
        bool inRegion(const Vec3d& worldPos);

    private:
        const ScalpSampler& mSampler;
        openvdb::FloatGrid::ConstAccessor mSurface;
        openvdb::Vec3SGrid::ConstAccessor mGradient;
        std::unique_ptr<openvdb::BoolGrid::ConstAccessor> mRegion;
    };

    double voxelSize() const { return mVoxelSize; }
    double halfWidthWorld() const { return mBackground; }
    const openvdb::FloatGrid& surface() const;

private:
    struct Impl;
    std::unique_ptr<Impl> mImpl;
    double mVoxelSize = 1.0, mBackground = 3.0;
};

} // namespace vdbhair
