#include "../TestUtil.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/Memory.h>
#include <vdbhair/io/VdbFile.h>
#include <vdbhair/io/VdbStrandGrid.h>

#include <openvdb/openvdb.h>
#include <openvdb/tools/LevelSetSphere.h>

#include <filesystem>

using namespace vdbhair;
using Catch::Matchers::Contains;

namespace {

/// The peak bytes readVdbGrids() holds reading @a path, over the file's size.
double peakPerFileByte(const std::string& path)
{
    AllocationBudget outer(std::numeric_limits<std::uint64_t>::max());
    const openvdb::GridPtrVec grids = readVdbGrids(path, path);
    REQUIRE(!grids.empty());
    return double(outer.peak()) / double(std::filesystem::file_size(path));
}

} // namespace

TEST_CASE("readVdbGrids: the densest files OpenVDB writes hold less than the read budget's factor", "[io][vdb]")
{
    // The read budget (readBudgetBytes) allows kReadBudgetPerFileByte bytes per byte of file. A
    // legitimate file expands most where its values compress best: fully active leaves of equal
    // values, of the widest type, with the default compression (Blosc when built in, else zip),
    // and where one voxel alone makes a branch of internal nodes (whose tables of 32^3 and 16^3
    // values are masks and a few compressed bytes in the file).
    openvdb::initialize();
    const auto denseEqual = [](auto grid, auto value, const std::string& name) {
        grid->denseFill(openvdb::CoordBBox(openvdb::Coord(0), openvdb::Coord(63)), value, /*active=*/true);
        grid->setName("v");
        const std::string path = test::tempPath(name);
        writeVdbGrids(path, {grid}, "test");
        return path;
    };
    const std::string vec3d = denseEqual(openvdb::Vec3DGrid::create(), openvdb::Vec3d(0.25, 0.5, 1.0), "dense_vec3d.vdb");
    const std::string fl = denseEqual(openvdb::FloatGrid::create(), 0.5f, "dense_float.vdb");
    auto sparse = openvdb::Vec3DGrid::create();
    for (int i = 0; i < 8; ++i) sparse->tree().setValue(openvdb::Coord(i * 4096, 0, 0), openvdb::Vec3d(1.0));
    sparse->setName("v");
    const std::string branches = test::tempPath("sparse_vec3d.vdb");
    writeVdbGrids(branches, {sparse}, "test");
    auto sphere = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(20.f, openvdb::Vec3f(0.f), 0.5f);
    const std::string ls = test::tempPath("sphere.vdb");
    writeVdbGrids(ls, {sphere}, "test");
    const std::string strands = test::tempPath("budget_strands.vdb");
    writeVdbStrands(strands, test::sampleStrands(true));

    for (const std::string& path : {vec3d, fl, branches, ls, strands}) {
        const double ratio = peakPerFileByte(path);
        INFO(path << ": peak " << ratio << " bytes per byte of file");
        CHECK(ratio > 0.5);
        CHECK(ratio < double(kReadBudgetPerFileByte));
    }
}

TEST_CASE("readVdbGrids: reading past the memory left to it is one LimitError naming the file", "[io][vdb]")
{
    openvdb::initialize();
    auto grid = openvdb::Vec3DGrid::create();
    grid->denseFill(openvdb::CoordBBox(openvdb::Coord(0), openvdb::Coord(63)), openvdb::Vec3d(1.0), true);
    grid->setName("v");
    const std::string path = test::tempPath("budget_dense.vdb");
    writeVdbGrids(path, {grid}, "test");
    {
        AllocationBudget outer(std::uint64_t(1) << 20);  // the grid holds 6 MiB of values
        REQUIRE_THROWS_AS(readVdbGrids(path, path), LimitError);
        REQUIRE_THROWS_WITH(readVdbGrids(path, path), Contains(path + ": reading it asks for") && Contains("left to this read"));
        REQUIRE_THROWS_AS(readVdbGrid(path, "v", path), LimitError);
        CHECK(outer.live() < (std::uint64_t(1) << 20));
    }
    CHECK(readVdbGrids(path, path).size() == 1);  // nothing kept from the refused reads
    CHECK(readBudgetBytes(1000, std::numeric_limits<std::uint64_t>::max()) == kReadBudgetFloor + 1000 * kReadBudgetPerFileByte);
    CHECK(readBudgetBytes(1000, 4096) == 4096);
    CHECK(readBudgetBytes(std::numeric_limits<std::uint64_t>::max(), 4096) == 4096);
}

TEST_CASE("readVdbGrids: the leaf chunk of -1000 bytes that overflows OpenVDB 10.0.1 is refused before OpenVDB reads it", "[io][vdb][fuzz]")
{
    // A fuzz seed (tests/fuzz/MakeSeeds.cc): a density field whose last leaf declares a chunk of
    // -1000 bytes for its 8-byte buffer. OpenVDB 10.0.1's readData() reads it uncompressed, 1,000
    // bytes into the 8 (a heap-buffer-overflow under AddressSanitizer; fixed in OpenVDB 11.0).
    const std::string path = test::regressionInput("fuzz_vdb_negative_chunk.vdb");
    REQUIRE_THROWS_AS(readVdbGrids(path, path), FormatError);
    REQUIRE_THROWS_WITH(readVdbGrids(path, path), Contains(path) && Contains("leaf values: uncompressed chunk of 1000 bytes for a destination of 8"));
    REQUIRE_THROWS_AS(readVdbGrid(path, "tangent", path), FormatError);
}

TEST_CASE("readVdbStrands: a points grid whose uniform arrays claim 268 million points in an 11 KB file ends at the read budget", "[io][vdb][fuzz]")
{
    // Found by fuzz_vdb: a leaf's offsets say 268,435,456 points, and its arrays are uniform (one
    // value stands for every point), so the file is valid to OpenVDB and small; expanding it to
    // strands asked for 3 GiB. The expansion runs in the file's read budget (withinReadBudget).
    const std::string path = test::regressionInput("fuzz_vdb_uniform_points.vdb");
    REQUIRE_THROWS_AS(readVdbStrands(path), LimitError);
    REQUIRE_THROWS_WITH(readVdbStrands(path), Contains(path) && Contains("past the budget of") && Contains("the file declares more data than it can hold"));
    CHECK(AllocationBudget::current() == nullptr);
}
