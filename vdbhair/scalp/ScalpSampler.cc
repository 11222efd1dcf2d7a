// The translation unit with OpenVDB's grid operators for scalp queries.
#include "ScalpSampler.h"

#include <vdbhair/Exceptions.h>

#include <openvdb/tools/GridOperators.h>
#include <openvdb/tools/Interpolation.h>

#include <cmath>

namespace vdbhair {

struct ScalpSampler::Impl
{
    openvdb::FloatGrid::ConstPtr surface;
    openvdb::BoolGrid::ConstPtr region;
    openvdb::Vec3SGrid::Ptr gradient;
};

ScalpSampler::ScalpSampler(openvdb::FloatGrid::ConstPtr surface, openvdb::BoolGrid::ConstPtr region)
    : mImpl(std::make_unique<Impl>())
{
    if (!surface) throw ValueError("ScalpSampler: no surface grid");
    if (surface->getGridClass() != openvdb::GRID_LEVEL_SET) {
        throw TypeError("ScalpSampler: grid '" + surface->getName() + "' is not a level set (class " +
                        openvdb::GridBase::gridClassToString(surface->getGridClass()) + ")");
    }
    if (!surface->hasUniformVoxels()) throw ValueError("ScalpSampler: grid '" + surface->getName() + "' has non-uniform voxels");
    if (region && region->transform() != surface->transform()) {
        throw ValueError("ScalpSampler: the region grid's transform differs from the surface's; regions are made on the surface's voxels");
    }
    mImpl->surface = surface;
    mImpl->region = region;
    mImpl->gradient = openvdb::tools::gradient(*surface);
    mVoxelSize = surface->voxelSize().x();
    mBackground = double(surface->background());
}

ScalpSampler::~ScalpSampler() = default;

const openvdb::FloatGrid& ScalpSampler::surface() const { return *mImpl->surface; }
bool ScalpSampler::hasRegion() const { return bool(mImpl->region); }

namespace {

// The queries, over trees or accessors alike.
template<typename SurfaceT>
double distanceAt(const openvdb::math::Transform& xf, const SurfaceT& surface, const Vec3d& worldPos)
{
    return double(openvdb::tools::BoxSampler::sample(surface, xf.worldToIndex(worldPos)));
}

template<typename GradientT>
Vec3d normalAt(const openvdb::math::Transform& xf, const GradientT& gradient, const Vec3d& worldPos)
{
    Vec3d g(openvdb::tools::BoxSampler::sample(gradient, xf.worldToIndex(worldPos)));
    const double len = g.length();
    return len > 0.0 ? g / len : Vec3d(0.0);
}

template<typename SurfaceT, typename GradientT>
Vec3d projectFrom(const openvdb::math::Transform& xf, const SurfaceT& surface, const GradientT& gradient, const Vec3d& worldPos,
                  double voxelSize, double maxStep, double tolVoxels, int maxSteps)
{
    Vec3d p = worldPos;
    for (int k = 0; k < maxSteps; ++k) {
        const Vec3d ijk = xf.worldToIndex(p);
        const double phi = double(openvdb::tools::BoxSampler::sample(surface, ijk));
        if (std::abs(phi) < tolVoxels * voxelSize) break;
        const Vec3d g(openvdb::tools::BoxSampler::sample(gradient, ijk));
        const double g2 = g.lengthSqr();
        if (!(g2 > 1e-12)) break;
        Vec3d step = g * (phi / g2);
        const double len = step.length();
        if (len > maxStep) step *= maxStep / len;  // never jump past the band
        p -= step;
    }
    return p;
}

} // namespace

double ScalpSampler::distance(const Vec3d& worldPos) const
{
    return distanceAt(mImpl->surface->transform(), mImpl->surface->tree(), worldPos);
}

Vec3d ScalpSampler::normal(const Vec3d& worldPos) const
{
    return normalAt(mImpl->gradient->transform(), mImpl->gradient->tree(), worldPos);
}

Vec3d ScalpSampler::project(const Vec3d& worldPos, double tolVoxels, int maxSteps) const
{
    return projectFrom(mImpl->surface->transform(), mImpl->surface->tree(), mImpl->gradient->tree(), worldPos, mVoxelSize,
                       mBackground, tolVoxels, maxSteps);
}

bool ScalpSampler::inRegion(const Vec3d& worldPos) const
{
    if (!mImpl->region) return true;
    const openvdb::Coord c = mImpl->region->transform().worldToIndexNodeCentered(worldPos);
    return mImpl->region->tree().isValueOn(c);
}

ScalpSampler::Local::Local(const ScalpSampler& sampler)
    : mSampler(sampler), mSurface(sampler.mImpl->surface->getConstAccessor()), mGradient(sampler.mImpl->gradient->getConstAccessor())
{
    if (sampler.mImpl->region) mRegion = std::make_unique<openvdb::BoolGrid::ConstAccessor>(sampler.mImpl->region->getConstAccessor());
}

double ScalpSampler::Local::distance(const Vec3d& worldPos)
{
    return distanceAt(mSampler.mImpl->surface->transform(), mSurface, worldPos);
}

Vec3d ScalpSampler::Local::normal(const Vec3d& worldPos)
{
    return normalAt(mSampler.mImpl->gradient->transform(), mGradient, worldPos);
}

Vec3d ScalpSampler::Local::project(const Vec3d& worldPos, double tolVoxels, int maxSteps)
{
    return projectFrom(mSampler.mImpl->surface->transform(), mSurface, mGradient, worldPos, mSampler.mVoxelSize,
                       mSampler.mBackground, tolVoxels, maxSteps);
}

bool ScalpSampler::Local::inRegion(const Vec3d& worldPos)
{
    if (!mRegion) return true;
    return mRegion->isValueOn(mSampler.mImpl->region->transform().worldToIndexNodeCentered(worldPos));
}

} // namespace vdbhair
