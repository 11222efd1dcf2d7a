#include "ScalpRegion.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/Version.h>
#include <vdbhair/scalp/ScalpSampler.h>

#include <cmath>

namespace vdbhair {

openvdb::BoolGrid::Ptr regionFromRoots(const openvdb::FloatGrid& surface, const std::vector<Vec3f>& roots, double radius,
                                       const std::string& source, std::uint64_t maxVoxels)
{
    const std::string where = "regionFromRoots(" + (source.empty() ? std::string("roots") : source) + ")";
    if (!(radius > 0.0) || !std::isfinite(radius)) throw ValueError(where + ": radius " + std::to_string(radius) + " must be a positive length");
    if (roots.empty()) throw ValueError(where + ": no roots; the region would be empty");
    const openvdb::FloatGrid::ConstPtr surf = surface.copy();
    const ScalpSampler sampler(surf);
    const double h = sampler.voxelSize();
    const int r = int(std::ceil(radius / h));
    const std::uint64_t perRoot = std::uint64_t(2 * r + 1) * std::uint64_t(2 * r + 1) * std::uint64_t(2 * r + 1);
    if (perRoot > maxVoxels / roots.size() + 1) {
        throw LimitError(where + ": radius " + std::to_string(radius) + " over " + std::to_string(roots.size()) + " roots visits about " +
                         std::to_string(perRoot * roots.size()) + " voxels, more than the cap of " + std::to_string(maxVoxels));
    }
    openvdb::BoolGrid::Ptr region = openvdb::BoolGrid::create(false);
    region->setTransform(surface.transform().copy());
    auto out = region->getAccessor();
    auto in = surface.getConstAccessor();
    const double band = double(surface.background());
    std::size_t used = 0;
    for (const Vec3f& root : roots) {
        const Vec3d p = sampler.project(Vec3d(root));
        if (!(std::abs(sampler.distance(p)) < 0.5 * h)) continue;  // no surface near this root
        ++used;
        const openvdb::Coord c = surface.transform().worldToIndexNodeCentered(p);
        for (int dx = -r; dx <= r; ++dx)
            for (int dy = -r; dy <= r; ++dy)
                for (int dz = -r; dz <= r; ++dz) {
                    const openvdb::Coord q = c.offsetBy(dx, dy, dz);
                    if ((surface.transform().indexToWorld(q) - p).length() > radius) continue;
                    if (!(std::abs(double(in.getValue(q))) < band) || !in.isValueOn(q)) continue;
                    out.setValueOn(q, true);
                }
    }
    if (used == 0 || region->activeVoxelCount() == 0) {
        throw LookupError(where + ": none of the " + std::to_string(roots.size()) +
                          " roots projects onto the surface's narrow band; the region is empty (are the roots and the scalp in the same units and place?)");
    }
    region->setName("region");
    region->setCreator("vdbhair " VDBHAIR_VERSION_STRING);
    region->insertMeta("vdbhair_region_kind", openvdb::StringMetadata("roots"));
    region->insertMeta("vdbhair_region_radius", openvdb::DoubleMetadata(radius));
    region->insertMeta("vdbhair_region_roots", openvdb::Int64Metadata(std::int64_t(used)));
    if (!source.empty()) region->insertMeta("vdbhair_source", openvdb::StringMetadata(source));
    return region;
}

} // namespace vdbhair
