#include "HairVolume.h"

#include <openvdb/tools/Morphology.h>

#include <algorithm>
#include <cmath>
#include <cstring>

namespace vdbhair {

HairVolume::HairVolume(const openvdb::Vec3SGrid& grid) : mMap(FieldMapping::fromGrid(grid)), mTree(false)
{
    mTree.topologyUnion(grid.tree());
    openvdb::tools::dilateActiveValues(mTree, 1, openvdb::tools::NN_FACE_EDGE_VERTEX, openvdb::tools::IGNORE_TILES);
}

bool HairVolume::Probe::containsSegment(const Vec3d& a, const Vec3d& b, double half)
{
    const std::size_t k = std::max<std::size_t>(1, std::size_t(std::ceil((b - a).length() / half)));
    for (std::size_t s = 1; s <= k; ++s) {
        if (!contains(a + (b - a) * (double(s) / double(k)))) return false;
    }
    return true;
}

bool HairVolume::Probe::containsPolyline(const Vec3f* p, std::size_t n)
{
    if (n == 0) return true;
    if (!contains(Vec3d(p[0]))) return false;
    const double half = 0.5 * mV.mMap.worldVoxelSize();
    for (std::size_t j = 0; j + 1 < n; ++j) {
        if (!containsSegment(Vec3d(p[j]), Vec3d(p[j + 1]), half)) return false;
    }
    return true;
}

bool HairVolume::Probe::containsChanged(const Vec3f* p, const Vec3f* ref, std::size_t n)
{
    if (n == 0) return true;
    auto same = [&](std::size_t j) { return std::memcmp(&p[j], &ref[j], sizeof(Vec3f)) == 0; };
    if (!same(0) && !contains(Vec3d(p[0]))) return false;
    const double half = 0.5 * mV.mMap.worldVoxelSize();
    bool prev = same(0);
    for (std::size_t j = 0; j + 1 < n; ++j) {
        const bool next = same(j + 1);
        if (!(prev && next) && !containsSegment(Vec3d(p[j]), Vec3d(p[j + 1]), half)) return false;
        prev = next;
    }
    return true;
}

} // namespace vdbhair
