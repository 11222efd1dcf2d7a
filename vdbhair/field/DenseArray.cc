#include "DenseArray.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/Parallel.h>

#include <openvdb/tools/Dense.h>

#include <cmath>
#include <string>

namespace vdbhair {

namespace {

std::string coordText(const openvdb::Coord& c)
{
    return "(" + std::to_string(c.x()) + ", " + std::to_string(c.y()) + ", " + std::to_string(c.z()) + ")";
}

template <typename GridT>
void copyBox(const GridT& grid, const openvdb::CoordBBox& indexBox, float* out, bool threaded)
{
    using ValueT = typename GridT::ValueType;
    if (indexBox.empty()) {
        throw ValueError("copyToDenseArray(" + grid.getName() + "): the index box " + coordText(indexBox.min()) + " .. " +
                         coordText(indexBox.max()) + " is empty; each max must be at least its min");
    }
    // LayoutXYZ: x varies fastest, so the array is [z][y][x] (Vec3s is three packed floats).
    openvdb::tools::Dense<ValueT, openvdb::tools::LayoutXYZ> dense(indexBox, reinterpret_cast<ValueT*>(out));
    openvdb::tools::copyToDense(grid, dense, /*serial=*/!threaded);
}

void checkBox(const DenseBox& box)
{
    const char* axes = "xyz";
    for (int a = 0; a < 3; ++a) {
        const std::string axis(1, axes[a]);
        if (box.size[a] < 1) throw ValueError("orientationVolume: " + std::to_string(box.size[a]) + " samples along " + axis + ": must be at least 1");
        if (!std::isfinite(box.worldMin[a]) || !std::isfinite(box.worldMax[a])) {
            throw ValueError("orientationVolume: the box's " + axis + " range is not finite");
        }
        if (!(box.worldMax[a] > box.worldMin[a])) {
            throw ValueError("orientationVolume: the box's " + axis + " range " + std::to_string(box.worldMin[a]) + " .. " +
                             std::to_string(box.worldMax[a]) + " is empty; max must be above min");
        }
    }
}

} // namespace

std::size_t denseSampleCount(const DenseBox& box)
{
    return std::size_t(box.size.x()) * std::size_t(box.size.y()) * std::size_t(box.size.z());
}

void copyToDenseArray(const openvdb::Vec3SGrid& grid, const openvdb::CoordBBox& indexBox, float* out, bool threaded)
{
    copyBox(grid, indexBox, out, threaded);
}

void copyToDenseArray(const openvdb::FloatGrid& grid, const openvdb::CoordBBox& indexBox, float* out, bool threaded)
{
    copyBox(grid, indexBox, out, threaded);
}

std::vector<float> orientationVolume(const openvdb::Vec3SGrid& tangent, const DenseBox& box, bool threaded)
{
    checkBox(box);
    const int w = box.size.x(), h = box.size.y(), d = box.size.z();
    std::vector<float> out(denseSampleCount(box) * 4, 0.0f);
    const openvdb::Vec3d cell = (box.worldMax - box.worldMin) / openvdb::Vec3d(w, h, d);
    const openvdb::math::Transform& xform = tangent.transform();

    // One row of W samples (fixed j, k) per call; one accessor per row, never shared.
    forEachIndex(std::size_t(h) * std::size_t(d), threaded, [&](std::size_t row) {
        const int j = int(row % std::size_t(h)), k = int(row / std::size_t(h));
        auto acc = tangent.getConstAccessor();
        float* o = out.data() + row * std::size_t(w) * 4;
        for (int i = 0; i < w; ++i, o += 4) {
            const openvdb::Vec3d world = box.worldMin + (openvdb::Vec3d(i, j, k) + 0.5) * cell;
            const openvdb::Vec3d index = xform.worldToIndex(world);
            const openvdb::Coord base = openvdb::Coord::floor(index);
            const openvdb::Vec3d f = index - base.asVec3d();
            // Trilinear weights over the 8 voxels around the sample; inactive voxels weigh 0.
            double occupancy = 0.0;
            openvdb::Vec3d dir(0.0);
            for (int corner = 0; corner < 8; ++corner) {
                const int dx = corner & 1, dy = (corner >> 1) & 1, dz = (corner >> 2) & 1;
                const double weight = (dx ? f.x() : 1.0 - f.x()) * (dy ? f.y() : 1.0 - f.y()) * (dz ? f.z() : 1.0 - f.z());
                openvdb::Vec3s v;
                if (weight > 0.0 && acc.probeValue(base.offsetBy(dx, dy, dz), v)) {
                    occupancy += weight;
                    dir += weight * openvdb::Vec3d(v);
                }
            }
            const double len = dir.length();
            if (occupancy > 0.0 && len > 1e-12) {
                o[0] = float(dir.x() / len);
                o[1] = float(dir.y() / len);
                o[2] = float(dir.z() / len);
            }
            o[3] = float(occupancy);
        }
    }, 1);
    return out;
}

} // namespace vdbhair
