#include "ScalpRegion.h"

#include <vdbhair/Format.h>

#include <vdbhair/strands/PointCloud.h>

#include <vdbhair/Exceptions.h>
#include <vdbhair/Version.h>
#include <vdbhair/io/VdbFile.h>
#include <vdbhair/scalp/ScalpSampler.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <optional>

#include <openvdb/tools/Interpolation.h>

namespace vdbhair {


std::vector<Vec3f> projectOntoSurface(const openvdb::FloatGrid& surface, const std::vector<Vec3f>& points, std::vector<char>* onSurface)
{
    const openvdb::FloatGrid::ConstPtr surf = surface.copy();
    const ScalpSampler sampler(surf);
    const double h = sampler.voxelSize();
    std::vector<Vec3d> crossing;  // centres of the voxels the zero level set passes near
    for (auto it = surface.cbeginValueOn(); it; ++it) {
        if (it.isVoxelValue() && std::abs(double(*it)) < h) crossing.push_back(surface.transform().indexToWorld(it.getCoord()));
    }
    std::vector<Vec3f> out(points.size());
    if (onSurface) onSurface->assign(points.size(), 0);
    if (crossing.empty()) return out;
    const PointCloud cloud{&crossing};
    const PointKdTree tree(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(16));
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, points.size(), 256), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
            const Vec3d q(points[i]);
            std::uint32_t idx = 0;
            double d2 = 0.0;
            tree.knnSearch(q.asPointer(), 1, &idx, &d2);
            // Start from the point itself when it is in the band, else from the nearest crossing.
            const Vec3d start = std::abs(sampler.distance(q)) < 0.9 * sampler.halfWidthWorld() ? q : crossing[idx];
            const Vec3d p = sampler.project(start);
            out[i] = Vec3f(p);
            if (onSurface) (*onSurface)[i] = std::abs(sampler.distance(p)) < 0.5 * h ? 1 : 0;
        }
    });
    return out;
}

openvdb::BoolGrid::Ptr regionFromRoots(const openvdb::FloatGrid& surface, const std::vector<Vec3f>& roots, double radius,
                                       const std::string& source, std::uint64_t maxVoxels, double maxDistance)
{
    const std::string where = "regionFromRoots(" + (source.empty() ? std::string("roots") : source) + ")";
    if (!(radius > 0.0) || !std::isfinite(radius)) throw ValueError(where + ": radius " + std::to_string(radius) + " must be a positive length");
    if (roots.empty()) throw ValueError(where + ": no roots; the region would be empty");
    const openvdb::FloatGrid::ConstPtr surf = surface.copy();
    const ScalpSampler sampler(surf);
    const double h = sampler.voxelSize();
    const int r = int(std::ceil(radius / h));
    // The roots that count: those with surface near them (projected within maxDistance). Counted
    // first, so roots in other units or another place are reported as such, not as a cost.
    std::vector<char> ok;
    const std::vector<Vec3f> projected = projectOntoSurface(surface, roots, &ok);
    std::size_t used = 0;
    for (std::size_t k = 0; k < roots.size(); ++k) {
        if (ok[k] && (Vec3d(projected[k]) - Vec3d(roots[k])).length() > maxDistance) ok[k] = 0;
        used += ok[k] ? 1 : 0;
    }
    if (used == 0) {
        throw LookupError(where + ": none of the " + std::to_string(roots.size()) + " roots is within " + formatNumber(maxDistance) +
                          " of the surface; the region is empty (are the roots and the scalp in the same units and place?)");
    }
    const std::uint64_t perRoot = std::uint64_t(2 * r + 1) * std::uint64_t(2 * r + 1) * std::uint64_t(2 * r + 1);
    if (perRoot > maxVoxels / used + 1) {
        throw LimitError(where + ": radius " + formatNumber(radius) + " (" + std::to_string(r) + " voxels) over " + std::to_string(used) +
                         " roots visits about " + std::to_string(perRoot * used) + " voxels, more than the cap of " + std::to_string(maxVoxels) +
                         " (is the radius in the scalp's units?)");
    }
    openvdb::BoolGrid::Ptr region = openvdb::BoolGrid::create(false);
    region->setTransform(surface.transform().copy());
    auto out = region->getAccessor();
    auto in = surface.getConstAccessor();
    const double band = double(surface.background());
    for (std::size_t k = 0; k < roots.size(); ++k) {
        if (!ok[k]) continue;  // no surface near this root
        const Vec3d p(projected[k]);
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
    if (region->activeVoxelCount() == 0) {
        throw LookupError(where + ": the " + std::to_string(used) + " roots near the surface cover no band voxel within " +
                          formatNumber(radius) + " of their projections; the region is empty");
    }
    region->setName("region");
    region->setCreator("vdbhair " VDBHAIR_VERSION_STRING);
    region->insertMeta("vdbhair_region_kind", openvdb::StringMetadata("roots"));
    region->insertMeta("vdbhair_region_radius", openvdb::DoubleMetadata(radius));
    region->insertMeta("vdbhair_region_roots", openvdb::Int64Metadata(std::int64_t(used)));
    if (!source.empty()) region->insertMeta("vdbhair_source", openvdb::StringMetadata(source));
    return region;
}

openvdb::BoolGrid::Ptr regionFromMask(const openvdb::FloatGrid& surface, const openvdb::GridBase& mask, double threshold,
                                      const std::string& source)
{
    const std::string where = "regionFromMask(" + (source.empty() ? mask.getName() : source + ": grid '" + mask.getName() + "'") + ")";
    if (!std::isfinite(threshold)) throw ValueError(where + ": threshold " + std::to_string(threshold) + " must be finite");
    const auto* boolMask = dynamic_cast<const openvdb::BoolGrid*>(&mask);
    const auto* floatMask = dynamic_cast<const openvdb::FloatGrid*>(&mask);
    if (!boolMask && !floatMask)
        throw TypeError(where + ": a region mask is a bool or float grid, not " + mask.valueType());
    openvdb::BoolGrid::Ptr region = openvdb::BoolGrid::create(false);
    region->setTransform(surface.transform().copy());
    auto out = region->getAccessor();
    const double band = double(surface.background());
    std::optional<openvdb::BoolGrid::ConstAccessor> bAcc;
    std::optional<openvdb::FloatGrid::ConstAccessor> fAcc;
    if (boolMask) bAcc.emplace(boolMask->getConstAccessor());
    if (floatMask) fAcc.emplace(floatMask->getConstAccessor());
    for (auto it = surface.cbeginValueOn(); it; ++it) {
        if (!(std::abs(double(*it)) < band)) continue;
        const openvdb::Coord c = it.getCoord();
        const Vec3d w = surface.transform().indexToWorld(c);
        bool in = false;
        if (boolMask) {
            in = bAcc->getValue(boolMask->transform().worldToIndexNodeCentered(w));
        } else {
            in = double(openvdb::tools::BoxSampler::sample(*fAcc, floatMask->transform().worldToIndex(w))) > threshold;
        }
        if (in) out.setValueOn(c, true);
    }
    if (region->activeVoxelCount() == 0)
        throw LookupError(where + ": the mask covers no voxel of the surface's band; the region would be empty (is it on the same head, in the same units?)");
    region->setName("region");
    region->setCreator("vdbhair " VDBHAIR_VERSION_STRING);
    region->insertMeta("vdbhair_region_kind", openvdb::StringMetadata("mask"));
    if (floatMask) region->insertMeta("vdbhair_region_threshold", openvdb::DoubleMetadata(threshold));
    if (!source.empty()) region->insertMeta("vdbhair_source", openvdb::StringMetadata(source));
    return region;
}

struct VertexValueSampler::Tree
{
    PointCloud cloud;
    PointKdTree tree;
    explicit Tree(const std::vector<Vec3d>& v) : cloud{&v}, tree(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(16)) {}
};

VertexValueSampler::VertexValueSampler(const TriangleMesh& mesh, std::vector<float> values, const std::string& where, int neighbors)
    : mVertices(mesh.vertices.begin(), mesh.vertices.end()), mValues(std::move(values)), mNeighbors(std::size_t(std::clamp(neighbors, 1, 4)))
{
    if (mValues.size() != mVertices.size())
        throw ValueError(where + ": " + std::to_string(mValues.size()) + " values for " + std::to_string(mVertices.size()) + " vertices; give one per vertex");
    if (mVertices.empty()) throw ValueError(where + ": the mesh has no vertices");
    mTree = std::make_unique<Tree>(mVertices);
}

VertexValueSampler::~VertexValueSampler() = default;

double VertexValueSampler::at(const Vec3d& p) const
{
    const std::size_t k = std::min<std::size_t>(mNeighbors, mVertices.size());
    std::uint32_t idx[4];
    double d2[4];
    const std::size_t found = mTree->tree.knnSearch(p.asPointer(), k, idx, d2);
    double sum = 0.0, weight = 0.0;
    for (std::size_t j = 0; j < found; ++j) {
        if (d2[j] == 0.0) return mValues[idx[j]];
        const double wj = 1.0 / std::sqrt(d2[j]);
        sum += wj * double(mValues[idx[j]]);
        weight += wj;
    }
    return weight > 0.0 ? sum / weight : 0.0;
}

openvdb::GridBase::Ptr readMaskGrid(const std::string& path, const std::string& name, const std::string& preferred, const std::string& option)
{
    std::string use = name;
    if (use.empty()) {
        const std::vector<std::string> names = vdbGridNames(path, path);
        if (!preferred.empty() && std::find(names.begin(), names.end(), preferred) != names.end()) use = preferred;
        for (std::size_t i = 0; use.empty() && i < names.size(); ++i) {
            const openvdb::GridBase::Ptr g = readVdbGrid(path, names[i], path);
            if ((g->isType<openvdb::BoolGrid>() || g->isType<openvdb::FloatGrid>()) && g->getGridClass() != openvdb::GRID_LEVEL_SET) use = names[i];
        }
        if (use.empty()) throw LookupError(path + ": no bool or float grid to use as " + option + " (a level set is a surface, not a mask)");
    }
    const openvdb::GridBase::Ptr g = readVdbGrid(path, use, path);
    if (!g->isType<openvdb::BoolGrid>() && !g->isType<openvdb::FloatGrid>()) {
        throw TypeError(path + ": grid '" + use + "' is a " + g->valueType() + " grid; " + option + " reads a bool or float grid");
    }
    return g;
}

openvdb::BoolGrid::Ptr regionFromVertexValues(const openvdb::FloatGrid& surface, const TriangleMesh& mesh, const std::vector<float>& values,
                                              double threshold, const std::string& source)
{
    const std::string where = "regionFromVertexValues(" + (source.empty() ? std::string("mesh") : source) + ")";
    if (!std::isfinite(threshold)) throw ValueError(where + ": threshold " + std::to_string(threshold) + " must be finite");
    const VertexValueSampler sampler(mesh, values, where);
    openvdb::BoolGrid::Ptr region = openvdb::BoolGrid::create(false);
    region->setTransform(surface.transform().copy());
    auto out = region->getAccessor();
    const double band = double(surface.background());
    for (auto it = surface.cbeginValueOn(); it; ++it) {
        if (!it.isVoxelValue() || !(std::abs(double(*it)) < band)) continue;
        const Vec3d w = surface.transform().indexToWorld(it.getCoord());
        if (sampler.at(w) > threshold) out.setValueOn(it.getCoord(), true);
    }
    if (region->activeVoxelCount() == 0)
        throw LookupError(where + ": no vertex value near the surface exceeds the threshold " + formatNumber(threshold) + "; the region would be empty");
    region->setName("region");
    region->setCreator("vdbhair " VDBHAIR_VERSION_STRING);
    region->insertMeta("vdbhair_region_kind", openvdb::StringMetadata("vertex"));
    region->insertMeta("vdbhair_region_threshold", openvdb::DoubleMetadata(threshold));
    if (!source.empty()) region->insertMeta("vdbhair_source", openvdb::StringMetadata(source));
    return region;
}

} // namespace vdbhair
