#include "../TestUtil.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/field/DenseArray.h>

using namespace vdbhair;
using Catch::Matchers::Contains;

namespace {

/// Every voxel of [0, n)^3 active with @a v, voxel size @a h.
openvdb::Vec3SGrid::Ptr uniformGrid(int n, const openvdb::Vec3s& v, double h)
{
    auto g = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
    g->setTransform(openvdb::math::Transform::createLinearTransform(h));
    g->denseFill(openvdb::CoordBBox(openvdb::Coord(0), openvdb::Coord(n - 1)), v, true);
    return g;
}

} // namespace

TEST_CASE("orientationVolume: a uniform field gives a constant volume inside and zero outside", "[field]")
{
    const openvdb::Vec3s dir = openvdb::Vec3s(1.0f, 2.0f, 2.0f) / 3.0f;
    const auto grid = uniformGrid(16, dir, 0.5);  // world [0, 7.5] (voxel centres)
    DenseBox box;
    box.worldMin = openvdb::Vec3d(1.0, 2.0, 3.0);
    box.worldMax = openvdb::Vec3d(6.0, 5.0, 4.0);
    box.size = openvdb::Coord(7, 5, 3);  // W, H, D
    const std::vector<float> v = orientationVolume(*grid, box);
    REQUIRE(v.size() == 3 * 5 * 7 * 4);
    for (std::size_t s = 0; s < v.size() / 4; ++s) {
        CAPTURE(s);
        REQUIRE(v[4 * s] == Approx(dir.x()).margin(1e-6));
        REQUIRE(v[4 * s + 1] == Approx(dir.y()).margin(1e-6));
        REQUIRE(v[4 * s + 2] == Approx(dir.z()).margin(1e-6));
        REQUIRE(v[4 * s + 3] == Approx(1.0).margin(1e-6));
    }

    // Far outside: zeros.
    box.worldMin = openvdb::Vec3d(20.0);
    box.worldMax = openvdb::Vec3d(30.0);
    for (float x : orientationVolume(*grid, box)) REQUIRE(x == 0.0f);
}

TEST_CASE("orientationVolume: layout is [z][y][x][channel], samples at cell centres, occupancy trilinear", "[field]")
{
    // One active voxel at index (2, 3, 4), voxel size 1: occupancy falls linearly to 0 one voxel away.
    auto g = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
    g->tree().setValueOn(openvdb::Coord(2, 3, 4), openvdb::Vec3s(0.0f, 0.0f, -1.0f));
    DenseBox box;
    box.worldMin = openvdb::Vec3d(0.0, 0.0, 0.0);
    box.worldMax = openvdb::Vec3d(8.0, 8.0, 8.0);
    box.size = openvdb::Coord(16, 8, 8);  // x cells of 0.5: sample i at x = 0.25 + 0.5 i
    const std::vector<float> v = orientationVolume(*g, box, false);
    auto at = [&](int i, int j, int k, int c) { return v[((std::size_t(k) * 8 + std::size_t(j)) * 16 + std::size_t(i)) * 4 + std::size_t(c)]; };
    // y = 3.5, z = 4.5: half a voxel from (3, 4) in y and z -> weights 0.5 * 0.5 at best.
    CHECK(at(4, 3, 4, 3) == Approx(0.25 * 0.75).margin(1e-6));  // x = 2.25
    CHECK(at(3, 3, 4, 3) == Approx(0.25 * 0.75).margin(1e-6));  // x = 1.75
    CHECK(at(4, 3, 4, 2) == Approx(-1.0).margin(1e-6));         // the direction is normalized
    CHECK(at(8, 3, 4, 3) == 0.0f);                               // x = 4.25: two voxels away
    CHECK(at(4, 3, 4, 0) == 0.0f);
}

TEST_CASE("orientationVolume: bad boxes are refused", "[field]")
{
    const auto grid = uniformGrid(2, openvdb::Vec3s(1.0f, 0.0f, 0.0f), 1.0);
    DenseBox box;
    box.size = openvdb::Coord(0, 1, 1);
    CHECK_THROWS_WITH(orientationVolume(*grid, box), Contains("0 samples along x: must be at least 1"));
    box.size = openvdb::Coord(1);
    box.worldMax = openvdb::Vec3d(1.0, 0.0, 1.0);
    CHECK_THROWS_WITH(orientationVolume(*grid, box), Contains("the box's y range 0.000000 .. 0.000000 is empty"));
}

TEST_CASE("copyToDenseArray: x varies fastest, inactive voxels give the background", "[field]")
{
    auto g = openvdb::FloatGrid::create(-1.0f);
    g->tree().setValueOn(openvdb::Coord(1, 0, 0), 5.0f);
    g->tree().setValueOn(openvdb::Coord(0, 1, 2), 7.0f);
    std::vector<float> out(2 * 2 * 3);
    copyToDenseArray(*g, openvdb::CoordBBox(openvdb::Coord(0), openvdb::Coord(1, 1, 2)), out.data());
    CHECK(out[1] == 5.0f);                  // (1, 0, 0): [0][0][1]
    CHECK(out[(2 * 2 + 1) * 2 + 0] == 7.0f); // (0, 1, 2): [2][1][0]
    CHECK(out[0] == -1.0f);
    CHECK_THROWS_AS(copyToDenseArray(*g, openvdb::CoordBBox(), out.data()), ValueError);
}
