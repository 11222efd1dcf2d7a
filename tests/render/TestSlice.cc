#include "../TestUtil.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/io/VdbFile.h>
#include <vdbhair/io/VdbInspect.h>
#include <vdbhair/render/SliceRenderer.h>

#include <openvdb/openvdb.h>

using namespace vdbhair;
using Catch::Matchers::Contains;

namespace {

/// A 16³ block of voxels of size 0.5 starting at index 0, with values v(i, j, k), written to @a name.
template<typename GridT, typename Fn>
std::string writeBlock(const std::string& name, const std::string& gridName, Fn&& value)
{
    initializeOpenVdb();
    auto grid = GridT::create();
    grid->setName(gridName);
    grid->setTransform(openvdb::math::Transform::createLinearTransform(0.5));
    auto acc = grid->getAccessor();
    for (int i = 0; i < 16; ++i)
        for (int j = 0; j < 16; ++j)
            for (int k = 0; k < 16; ++k) acc.setValueOn(openvdb::Coord(i, j, k), value(i, j, k));
    const std::string path = test::tempPath(name);
    writeVdbGrids(path, {grid}, "test");
    return path;
}

/// The plot's pixel at fractions (fx, fy) of its width and height (the plot starts at (12, 34)).
Vec3f plotPixel(const SliceResult& r, int plotW, double fx, double fy)
{
    const int plotH = int(std::lround(plotW * 1.0));  // the blocks are square in every plane
    return r.image.at(12 + int(fx * plotW), 34 + int(fy * plotH));
}

} // namespace

TEST_CASE("renderSlice: a uniform vector field is one colour, RGB by |x|,|y|,|z| and HSV by in-plane angle", "[render]")
{
    const std::string path = writeBlock<openvdb::Vec3SGrid>("uniform_z.vdb", "tangent", [](int, int, int) { return openvdb::Vec3s(0, 0, 1); });
    SliceParams p;
    p.axis = 2;
    p.world = 4.0;
    p.width = 200;
    SliceResult r = renderSlice(path, "tangent", p);
    REQUIRE(r.indexPlane == 8);
    REQUIRE(r.activeVoxels == 256);
    REQUIRE(r.lo == Approx(1.0));
    for (double f : {0.1, 0.5, 0.9}) {
        const Vec3f c = plotPixel(r, 200, f, f);
        CAPTURE(f, c);
        REQUIRE(c.x() == Approx(0.0).margin(1e-6));
        REQUIRE(c.y() == Approx(0.0).margin(1e-6));
        REQUIRE(c.z() == Approx(1.0));  // pure blue: the field points along z
    }
    // In-plane directions: +x is red (hue 0) and -x cyan (hue 1/2) in HSV; RGB cannot tell them apart.
    const std::string px = writeBlock<openvdb::Vec3SGrid>("plus_x.vdb", "tangent", [](int, int, int) { return openvdb::Vec3s(1, 0, 0); });
    const std::string mx = writeBlock<openvdb::Vec3SGrid>("minus_x.vdb", "tangent", [](int, int, int) { return openvdb::Vec3s(-1, 0, 0); });
    p.color = SliceColor::Hsv;
    const Vec3f red = plotPixel(renderSlice(px, "tangent", p), 200, 0.5, 0.5);
    const Vec3f cyan = plotPixel(renderSlice(mx, "tangent", p), 200, 0.5, 0.5);
    REQUIRE(red.x() == Approx(1.0));
    REQUIRE(red.y() == Approx(0.0).margin(1e-6));
    REQUIRE(cyan.x() == Approx(0.0).margin(1e-6));
    REQUIRE(cyan.y() == Approx(1.0));
    REQUIRE(cyan.z() == Approx(1.0));
    p.color = SliceColor::Rgb;
    REQUIRE(plotPixel(renderSlice(px, "tangent", p), 200, 0.5, 0.5).x() == plotPixel(renderSlice(mx, "tangent", p), 200, 0.5, 0.5).x());
}

TEST_CASE("renderSlice: streamlines of a uniform in-plane field are straight lines along it", "[render]")
{
    const std::string path = writeBlock<openvdb::Vec3SGrid>("plus_x_lines.vdb", "tangent", [](int, int, int) { return openvdb::Vec3s(1, 0, 0); });
    SliceParams p;
    p.axis = 2;
    p.world = 4.0;
    p.width = 200;
    const SliceResult plain = renderSlice(path, "tangent", p);
    p.streamlines = 5;
    const SliceResult lines = renderSlice(path, "tangent", p);
    REQUIRE(lines.streamlinesDrawn == 5);
    // Changed pixels lie in a few horizontal bands (the lines) spanning the whole width.
    std::vector<int> changedPerRow(200, 0);
    for (int y = 0; y < 200; ++y) {
        for (int x = 0; x < 200; ++x) {
            const Vec3f a = plain.image.at(12 + x, 34 + y), b = lines.image.at(12 + x, 34 + y);
            if ((a - b).length() > 1e-3f) ++changedPerRow[std::size_t(y)];
        }
    }
    int fullRows = 0, touched = 0;
    for (int c : changedPerRow) { fullRows += c > 180; touched += c > 0; }
    REQUIRE(fullRows >= 5);
    REQUIRE(touched <= 5 * 6);  // each line at most ~5 pixels thick
    // Deterministic.
    const SliceResult again = renderSlice(path, "tangent", p);
    REQUIRE(again.image.rgb == lines.image.rgb);
}

TEST_CASE("renderSlice: a scalar ramp through the colour map; bad slices fail clearly", "[render]")
{
    const std::string path = writeBlock<openvdb::FloatGrid>("ramp.vdb", "density", [](int i, int, int) { return float(i); });
    SliceParams p;
    p.axis = 2;
    p.world = 4.0;
    p.width = 320;
    const SliceResult r = renderSlice(path, "density", p);
    REQUIRE(r.lo == 0.0);
    REQUIRE(r.hi == 15.0);
    // Left is the map's low end, right its high end, and brightness rises along x.
    REQUIRE((plotPixel(r, 320, 0.01, 0.5) - colorMap(0.f)).length() < 1e-6f);
    REQUIRE((plotPixel(r, 320, 0.99, 0.5) - colorMap(1.f)).length() < 1e-6f);
    // An x slice shows -z to the right: the ramp runs along the image's horizontal no more.
    p.axis = 0;
    p.world = 0.1;
    const SliceResult side = renderSlice(path, "density", p);
    REQUIRE(side.lo == 0.0);
    REQUIRE(side.hi == 0.0);

    p.axis = 2;
    p.world = 9.0;  // the block spans z from -0.25 to 7.75
    REQUIRE_THROWS_WITH(renderSlice(path, "density", p), Contains("slice z=9 is outside its active voxels, which span z from -0.25 to 7.75"));
    p.world = 4.0;
    REQUIRE_THROWS_AS(renderSlice(path, "nope", p), LookupError);
    int axis;
    double world;
    REQUIRE_THROWS_WITH(parseSlice("w=3", axis, world), Contains("expected AXIS=WORLD"));
    REQUIRE_THROWS_WITH(parseSlice("z=3cm", axis, world), Contains("expected AXIS=WORLD"));
    REQUIRE_THROWS_WITH(parseSlice("z=nan", axis, world), Contains("expected AXIS=WORLD"));
    parseSlice("y=-2.5e1", axis, world);
    REQUIRE(axis == 1);
    REQUIRE(world == -25.0);
}

TEST_CASE("inspectVdbFile: statistics of known values, tiles counted per voxel", "[render]")
{
    initializeOpenVdb();
    auto grid = openvdb::FloatGrid::create();
    grid->setName("known");
    grid->tree().addTile(1, openvdb::Coord(0), 2.0f, true);  // one 8³ tile of 2
    grid->tree().setValueOn(openvdb::Coord(100, 0, 0), 10.0f);
    const std::string path = test::tempPath("known.vdb");
    writeVdbGrids(path, {grid}, "test");
    const std::vector<GridReport> reports = inspectVdbFile(path);
    REQUIRE(reports.size() == 1);
    const GridReport& r = reports[0];
    REQUIRE(r.isScalar);
    REQUIRE(r.values.count == 513);
    REQUIRE(r.values.min == 2.0);
    REQUIRE(r.values.max == 10.0);
    REQUIRE(r.values.mean == Approx((512 * 2.0 + 10.0) / 513.0));
    REQUIRE(r.values.p50 == 2.0);
    REQUIRE(r.tilesByLevel[2] == 1);
    REQUIRE(r.info.activeTiles == 1);
    REQUIRE(r.info.leafNodes == 1);
    REQUIRE(r.leafFillMean == Approx(1.0 / 512.0));
    REQUIRE(r.indexMin == std::array<int, 3>{{0, 0, 0}});
    REQUIRE(r.indexMax == std::array<int, 3>{{100, 7, 7}});
}

TEST_CASE("inspectVdbFile: one grid by name, the others named when it is missing", "[render]")
{
    initializeOpenVdb();
    auto a = openvdb::FloatGrid::create();
    a->setName("density");
    a->tree().setValueOn(openvdb::Coord(0), 1.0f);
    auto b = openvdb::Vec3SGrid::create();
    b->setName("tangent");
    b->tree().setValueOn(openvdb::Coord(0), openvdb::Vec3s(1.f, 0.f, 0.f));
    const std::string path = test::tempPath("two_grids.vdb");
    writeVdbGrids(path, {a, b}, "test");
    REQUIRE(inspectVdbFile(path, "").size() == 2);
    const std::vector<GridReport> only = inspectVdbFile(path, "tangent");
    REQUIRE(only.size() == 1);
    CHECK(only[0].info.name == "tangent");
    CHECK(only[0].isVector);
    REQUIRE_THROWS_AS(inspectVdbFile(path, "nope"), LookupError);
    REQUIRE_THROWS_WITH(inspectVdbFile(path, "nope"), path + ": no grid named 'nope' (the file has: density, tangent)");
}

TEST_CASE("chooseSliceGrid: the grid asked for, else 'tangent', else the first voxel grid; never points", "[render]")
{
    auto report = [](const std::string& name, bool points) {
        GridReport r;
        r.info.name = name;
        r.info.isPoints = points;
        return r;
    };
    const std::vector<GridReport> all = {report("strands", true), report("density", false), report("tangent", false)};
    CHECK(chooseSliceGrid(all, "", "f.vdb") == "tangent");
    CHECK(chooseSliceGrid(all, "density", "f.vdb") == "density");
    CHECK(chooseSliceGrid({report("strands", true), report("density", false), report("hair_length", false)}, "", "f.vdb") == "density");
    REQUIRE_THROWS_WITH(chooseSliceGrid({report("strands", true)}, "", "f.vdb"), "f.vdb: has no voxel grid to slice (only points)");
}
