#include "RootGrid.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/Version.h>
#include <vdbhair/io/VdbFile.h>
#include <vdbhair/io/VdbStrandGrid.h>

#include <openvdb/points/PointAttribute.h>
#include <openvdb/points/PointConversion.h>
#include <openvdb/points/PointGroup.h>
#include <openvdb/tools/PointIndexGrid.h>

#include <algorithm>

namespace vdbhair {

namespace pts = openvdb::points;

openvdb::points::PointDataGrid::Ptr createRootGrid(const OrientedPoints& roots, unsigned pointsPerVoxel)
{
    initializeOpenVdb();
    const std::string where = "createRootGrid";
    const std::size_t n = roots.size();
    if (n == 0) throw ValueError(where + ": no roots; there is nothing to write");
    if (roots.normals.size() != n || (!roots.tangents.empty() && roots.tangents.size() != n)) {
        throw ValueError(where + ": " + std::to_string(roots.normals.size()) + " normals and " + std::to_string(roots.tangents.size()) +
                         " tangents for " + std::to_string(n) + " roots; roots need one normal each");
    }
    const pts::PointAttributeVector<openvdb::Vec3f> positions(roots.positions);
    double voxelSize = n > 1 ? pointsVoxelSize(roots.positions, std::max(1u, pointsPerVoxel)) : 1.0;
    voxelSize = std::max(voxelSize, 2e-5);
    const openvdb::math::Transform::Ptr xform = openvdb::math::Transform::createLinearTransform(voxelSize);
    const openvdb::tools::PointIndexGrid::Ptr index =
        openvdb::tools::createPointIndexGrid<openvdb::tools::PointIndexGrid>(positions, *xform);
    pts::PointDataGrid::Ptr grid = pts::createPointDataGrid<pts::NullCodec, pts::PointDataGrid>(*index, positions, *xform);
    pts::PointDataTree& tree = grid->tree();
    pts::appendAttribute<openvdb::Vec3f>(tree, "N");
    pts::populateAttribute(tree, index->tree(), "N", pts::PointAttributeVector<openvdb::Vec3f>(roots.normals));
    if (!roots.tangents.empty()) {
        pts::appendAttribute<openvdb::Vec3f>(tree, "tangent");
        pts::populateAttribute(tree, index->tree(), "tangent", pts::PointAttributeVector<openvdb::Vec3f>(roots.tangents));
    }
    pts::appendGroup(tree, "root");
    const std::vector<short> all(n, 1);
    pts::setGroup(tree, index->tree(), all, "root");
    grid->setName("roots");
    grid->setCreator("vdbhair " VDBHAIR_VERSION_STRING);
    grid->insertMeta("vdbhair_root_count", openvdb::Int64Metadata(std::int64_t(n)));
    return grid;
}

} // namespace vdbhair
