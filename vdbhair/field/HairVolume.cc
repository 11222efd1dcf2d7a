#include "HairVolume.h"

#include <openvdb/tools/Morphology.h>

#include <algorithm>
#include <cmath>

namespace vdbhair {

HairVolume::HairVolume(const openvdb::Vec3SGrid& grid) : mMap(FieldMapping::fromGrid(grid)), mTree(false)
{
    mTree.topologyUnion(grid.tree());
    openvdb::tools::dilateActiveValues(mTree, 1, openvdb::tools::NN_FACE_EDGE_VERTEX, openvdb::tools::IGNORE_TILES);
}

bool HairVolume::Probe::containsPolyline(const Vec3f* p, std::size_t n)
{
    if (n == 0) return true;
    if (!contains(Vec3d(p[0]))) return false;
    const double half = 0.5 * mV.mMap.worldVoxelSize();
    for (std::size_t j = 0; j + 1 < n; ++j) {
        const Vec3d a(p[j]), b(p[j + 1]);
        const std::size_t k = std::max<std::size_t>(1, std::size_t(std::ceil((b - a).length() / half)));
        for (std::size_t s = 1; s <= k; ++s) {
            if (!contains(a + (b - a) * (double(s) / double(k)))) return false;
        }
    }
    return true;
}

} // namespace vdbhair
