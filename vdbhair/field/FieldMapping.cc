#include "FieldMapping.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/Version.h>
#include <vdbhair/field/ScalpMap.h>
#include <vdbhair/io/MetaKeys.h>

#include <openvdb/Metadata.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace vdbhair {

const char* fieldSpaceName(FieldSpace space) { return space == FieldSpace::Scalp ? "scalp" : "world"; }

FieldSpace fieldSpaceFromName(const std::string& name)
{
    if (name == "world") return FieldSpace::World;
    if (name == "scalp") return FieldSpace::Scalp;
    throw ValueError("space '" + name + "' is not one of world, scalp");
}

std::string tangentGridName(int level, int levels)
{
    return levels <= 1 ? "tangent" : "tangent_level_" + std::to_string(level);
}

std::string hairLengthGridName(int level, int levels)
{
    return levels <= 1 ? "hair_length" : "hair_length_level_" + std::to_string(level);
}

std::string densityGridName(int level, int levels)
{
    return levels <= 1 ? "density" : "density_level_" + std::to_string(level);
}

std::string coherenceGridName(int level, int levels)
{
    return levels <= 1 ? "coherence" : "coherence_level_" + std::to_string(level);
}

std::string spreadGridName(int level, int levels)
{
    return levels <= 1 ? "spread" : "spread_level_" + std::to_string(level);
}

FieldMapping::FieldMapping(openvdb::math::Transform::ConstPtr xform) : mXform(std::move(xform))
{
    // Axis-aligned linear transforms (scale and translation only) take the fast path.
    if (mXform->isLinear()) {
        const openvdb::Mat4d m = mXform->baseMap()->getAffineMap()->getMat4();
        const bool diagonal = m(0, 1) == 0.0 && m(0, 2) == 0.0 && m(1, 0) == 0.0 && m(1, 2) == 0.0 &&
                              m(2, 0) == 0.0 && m(2, 1) == 0.0;
        if (diagonal && m(0, 0) != 0.0 && m(1, 1) != 0.0 && m(2, 2) != 0.0) {
            mDiagonal = true;
            mInvScale = openvdb::Vec3d(1.0 / m(0, 0), 1.0 / m(1, 1), 1.0 / m(2, 2));
            mOffset = openvdb::Vec3d(m(3, 0), m(3, 1), m(3, 2));
        }
    }
}

FieldMapping::FieldMapping(openvdb::math::Transform::ConstPtr xform, const ScalpSphere& scalp)
    : FieldMapping(std::move(xform))
{
    mSpace = FieldSpace::Scalp;
    mScalp = scalp;
}

FieldMapping::FieldMapping(openvdb::math::Transform::ConstPtr xform, std::shared_ptr<const ScalpMap> surface)
    : FieldMapping(std::move(xform))
{
    if (!surface) throw ValueError("FieldMapping: no scalp map");
    mSpace = FieldSpace::Scalp;
    mScalp = surface->sphere();
    if (surface->hasSurface()) mSurface = std::move(surface);
}

openvdb::Vec3d FieldMapping::toScalp(const openvdb::Vec3d& world) const
{
    const Vec3d p(world.x(), world.y(), world.z());
    return mSurface ? mSurface->toScalp(p) : worldToScalp(mScalp, p);
}

double FieldMapping::worldVoxelSize() const
{
    const double h = mXform->voxelSize().x();
    return mSpace == FieldSpace::Scalp ? h * mScalp.radius : h;
}

FieldMapping FieldMapping::fromGrid(const openvdb::GridBase& grid)
{
    const auto space = findVdbhairMeta<openvdb::StringMetadata>(grid, "space");
    if (!space || space->value() != "scalp") return FieldMapping(grid.constTransformPtr());
    const auto center = findVdbhairMeta<openvdb::Vec3DMetadata>(grid, "scalp_center");
    const auto radius = findVdbhairMeta<openvdb::DoubleMetadata>(grid, "scalp_radius");
    const auto up = findVdbhairMeta<openvdb::Vec3DMetadata>(grid, "scalp_up");
    if (!center || !radius || !up || !(radius->value() > 0.0)) {
        throw FormatError("grid '" + grid.getName() + "' is in scalp space but lacks a valid vdbhair_scalp_center, "
                          "vdbhair_scalp_radius (> 0) and vdbhair_scalp_up");
    }
    ScalpSphere s;
    s.center = Vec3d(center->value().x(), center->value().y(), center->value().z());
    s.radius = radius->value();
    s.up = Vec3d(up->value().x(), up->value().y(), up->value().z()).unitSafe();
    const auto table = findVdbhairMeta<openvdb::StringMetadata>(grid, "scalp_distance");
    if (!table) return FieldMapping(grid.constTransformPtr(), s);
    const auto resolution = findVdbhairMeta<openvdb::Int32Metadata>(grid, "scalp_resolution");
    const std::string where = "grid '" + grid.getName() + "': vdbhair_scalp_distance";
    if (!resolution || resolution->value() < ScalpMap::kMinResolution || resolution->value() > ScalpMap::kMaxResolution) {
        throw FormatError(where + " needs vdbhair_scalp_resolution in [" + std::to_string(ScalpMap::kMinResolution) + ", " +
                          std::to_string(ScalpMap::kMaxResolution) + "]");
    }
    // The count is bounded by the checked resolution before anything is allocated.
    const std::size_t count = std::size_t(resolution->value()) * std::size_t(resolution->value());
    std::vector<float> d;
    d.reserve(count);
    const char* c = table->value().c_str();
    while (true) {
        while (*c == ' ') ++c;
        if (!*c) break;
        char* end = nullptr;
        const float value = std::strtof(c, &end);
        if (end == c || (*end && *end != ' ')) throw FormatError(where + ": value " + std::to_string(d.size()) + " is not a number");
        if (d.size() == count) throw FormatError(where + " has more than the " + std::to_string(count) + " values of its resolution");
        d.push_back(value);
        c = end;
    }
    try {
        return FieldMapping(grid.constTransformPtr(), std::make_shared<const ScalpMap>(s, std::move(d), resolution->value()));
    } catch (const ValueError& e) {
        throw FormatError(where + ": " + e.what());
    }
}

void setFieldMetadata(openvdb::GridBase& grid, double voxelSize, int iterations, FieldSpace space,
                      const ScalpSphere& scalp, int level, int levels, std::size_t strandCount, const ScalpMap* surface)
{
    grid.insertMeta("creator", openvdb::StringMetadata(creatorString()));
    grid.insertMeta("vdbhair_voxel_size", openvdb::DoubleMetadata(voxelSize));
    grid.insertMeta("vdbhair_iterations", openvdb::Int32Metadata(iterations));
    grid.insertMeta("vdbhair_space", openvdb::StringMetadata(fieldSpaceName(space)));
    grid.insertMeta("vdbhair_level", openvdb::Int32Metadata(level));
    grid.insertMeta("vdbhair_levels", openvdb::Int32Metadata(levels));
    grid.insertMeta("vdbhair_strand_count", openvdb::Int64Metadata(std::int64_t(strandCount)));
    if (space == FieldSpace::Scalp) {
        grid.insertMeta("vdbhair_scalp_center", openvdb::Vec3DMetadata(openvdb::Vec3d(scalp.center.x(), scalp.center.y(), scalp.center.z())));
        grid.insertMeta("vdbhair_scalp_radius", openvdb::DoubleMetadata(scalp.radius));
        grid.insertMeta("vdbhair_scalp_up", openvdb::Vec3DMetadata(openvdb::Vec3d(scalp.up.x(), scalp.up.y(), scalp.up.z())));
        if (surface && surface->hasSurface()) {
            std::string text;
            text.reserve(surface->distances().size() * 12);
            char buf[32];
            for (float v : surface->distances()) {
                std::snprintf(buf, sizeof buf, text.empty() ? "%.9g" : " %.9g", double(v));
                text += buf;
            }
            grid.insertMeta("vdbhair_scalp_resolution", openvdb::Int32Metadata(surface->resolution()));
            grid.insertMeta("vdbhair_scalp_distance", openvdb::StringMetadata(text));
        }
    }
}

} // namespace vdbhair
