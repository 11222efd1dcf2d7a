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

double ScalpSampler::distance(const Vec3d& worldPos) const
{
    const Vec3d ijk = mImpl->surface->transform().worldToIndex(worldPos);
    return double(openvdb::tools::BoxSampler::sample(mImpl->surface->tree(), ijk));
}

Vec3d ScalpSampler::normal(const Vec3d& worldPos) const
{
    const Vec3d ijk = mImpl->gradient->transform().worldToIndex(worldPos);
    Vec3d g(openvdb::tools::BoxSampler::sample(mImpl->gradient->tree(), ijk));
    const double len = g.length();
    return len > 0.0 ? g / len : Vec3d(0.0);
}

Vec3d ScalpSampler::project(const Vec3d& worldPos, double tolVoxels, int maxSteps) const
{
    Vec3d p = worldPos;
    const auto& xf = mImpl->surface->transform();
    for (int k = 0; k < maxSteps; ++k) {
        const Vec3d ijk = xf.worldToIndex(p);
        const double phi = double(openvdb::tools::BoxSampler::sample(mImpl->surface->tree(), ijk));
        if (std::abs(phi) < tolVoxels * mVoxelSize) break;
        const Vec3d g(openvdb::tools::BoxSampler::sample(mImpl->gradient->tree(), ijk));
        const double g2 = g.lengthSqr();
        if (!(g2 > 1e-12)) break;
        Vec3d step = g * (phi / g2);
        const double len = step.length(), maxStep = mBackground;  // never jump past the band
        if (len > maxStep) step *= maxStep / len;
        p -= step;
    }
    return p;
}

bool ScalpSampler::inRegion(const Vec3d& worldPos) const
{
    if (!mImpl->region) return true;
    const openvdb::Coord c = mImpl->region->transform().worldToIndexNodeCentered(worldPos);
    return mImpl->region->tree().isValueOn(c);
}

} // namespace vdbhair
