#include "HairVolume.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/Parallel.h>

#include <openvdb/tools/Morphology.h>

#include <tbb/enumerable_thread_specific.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>

namespace vdbhair {

HairVolume::HairVolume(const openvdb::Vec3SGrid& grid) : mMap(FieldMapping::fromGrid(grid)), mTree(false)
{
    mTree.topologyUnion(grid.tree());
    openvdb::tools::dilateActiveValues(mTree, 1, openvdb::tools::NN_FACE_EDGE_VERTEX, openvdb::tools::IGNORE_TILES);
}

namespace {

/// The checks of HairVolume(strands, voxel) on one hairstyle: its reach from the origin in voxels
/// and the points its longest segment takes.
void checkVoxel(const StrandSet& s, double voxel)
{
    if (!(voxel > 0.0) || !std::isfinite(voxel)) throw ValueError("voxel " + std::to_string(voxel) + ": must be a positive length");
    double reach = 0.0, longest = 0.0;
    for (std::size_t i = 0; i < s.numStrands(); ++i) {
        const Vec3f* p = s.data(i);
        for (std::size_t k = 0; k < s.size(i); ++k) {
            reach = std::max({reach, double(std::abs(p[k].x())), double(std::abs(p[k].y())), double(std::abs(p[k].z()))});
            if (k + 1 < s.size(i)) longest = std::max(longest, double((p[k + 1] - p[k]).length()));
        }
    }
    if (!(reach / voxel < double(1 << 19))) {
        throw ValueError("voxel " + std::to_string(voxel) + ": over 2^19 voxels from the origin to the hair (" + std::to_string(reach) + "); give a larger voxel");
    }
    if (!(longest / (0.5 * voxel) < double(1 << 24))) {
        throw ValueError("voxel " + std::to_string(voxel) + ": a segment " + std::to_string(longest) + " long would take over 2^24 points");
    }
}

} // namespace

HairVolume::HairVolume(const StrandSet& reference, double voxel, bool threaded)
    : mMap(openvdb::math::Transform::createLinearTransform(voxel)), mTree(false)
{
    checkVoxel(reference, voxel);
    // Each thread marks its strands' voxels in a tree of its own; their union is the same whatever
    // the threads took.
    tbb::enumerable_thread_specific<openvdb::BoolTree> trees(false);
    forEachRange(reference.numStrands(), threaded, 64, [&](const tbb::blocked_range<std::size_t>& r) {
        openvdb::BoolTree& tree = trees.local();
        openvdb::tree::ValueAccessor<openvdb::BoolTree> acc(tree);
        const double inv = 1.0 / voxel;
        openvdb::Coord last = openvdb::Coord::max();  // nearestVoxel() never gives it
        auto mark = [&](const Vec3d& q) {
            const openvdb::Coord ijk = nearestVoxel(q);
            if (ijk == last) return;  // points along a strand: often the same voxel
            acc.setValueOn(ijk);
            last = ijk;
        };
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
            const Vec3f* p = reference.data(i);
            const std::size_t n = reference.size(i);
            for (std::size_t k = 0; k < n; ++k) {
                const Vec3d a = Vec3d(p[k]) * inv;  // in voxels
                mark(a);
                if (k + 1 == n) break;
                const Vec3d d = Vec3d(p[k + 1]) * inv - a;
                const std::size_t m = std::max<std::size_t>(1, std::size_t(std::ceil(2.0 * d.length())));  // half a voxel apart
                const Vec3d step = d / double(m);
                for (std::size_t j = 1; j < m; ++j) mark(a + step * double(j));
            }
        }
    });
    for (openvdb::BoolTree& tree : trees) mTree.topologyUnion(tree);
    openvdb::tools::dilateActiveValues(mTree, 1, openvdb::tools::NN_FACE_EDGE_VERTEX, openvdb::tools::IGNORE_TILES);
}

std::size_t countStrandsLeavingVolume(const StrandSet& strands, const StrandSet& reference, double voxel, bool threaded)
{
    checkVoxel(strands, voxel);
    const HairVolume volume(reference, voxel, threaded);
    std::vector<char> leaves(strands.numStrands(), 0);
    forEachRange(strands.numStrands(), threaded, 256, [&](const tbb::blocked_range<std::size_t>& r) {
        HairVolume::Probe probe(volume);
        for (std::size_t i = r.begin(); i != r.end(); ++i) leaves[i] = probe.containsPolyline(strands.data(i), strands.size(i)) ? 0 : 1;
    });
    std::size_t count = 0;
    for (const char c : leaves) count += std::size_t(c);
    return count;
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
