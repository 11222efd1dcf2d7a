#include "../TestUtil.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/io/ConvdataFile.h>

using namespace vdbhair;
using Catch::Matchers::Contains;

namespace {
std::string npy(const std::string& dict, const std::string& data)
{
    std::string h = dict;
    while ((10 + h.size() + 1) % 64) h += ' ';
    h += '\n';
    std::string b = "\x93NUMPY";
    b += char(1);
    b += char(0);
    test::put(b, std::uint16_t(h.size()));
    return b + h + data;
}
} // namespace

TEST_CASE("readConvdata: points per slot, root first; empty slots skipped", "[io]")
{
    // Shape (8, 1, 2): 2 points, 2 slots; slot 1 all zero.
    std::string data;
    const float v[8][2] = {{1, 0}, {2, 0}, {3, 0}, {0.5f, 0}, {4, 0}, {5, 0}, {6, 0}, {0.5f, 0}};
    for (const auto& row : v) for (float x : row) test::put(data, x);
    ReadReport report;
    const StrandSet s = readConvdata(test::writeBytes("a.convdata", npy("{'descr': '<f4', 'fortran_order': False, 'shape': (8, 1, 2), }", data)), {}, &report);
    REQUIRE(s.numStrands() == 1);
    REQUIRE(s.root(0) == Vec3f(1.f, 2.f, 3.f));
    REQUIRE(s.tip(0) == Vec3f(4.f, 5.f, 6.f));
    REQUIRE_THAT(report.warnings.at(0), Contains("skipped 1 empty (all-zero) strand slots of 2"));

    REQUIRE_THROWS_WITH(readConvdata(test::writeBytes("b.convdata", "NUMPY....")), Contains("not a NumPy .npy file"));
    REQUIRE_THROWS_AS(readConvdata(test::writeBytes("c.convdata", npy("{'descr': '<f8', 'fortran_order': False, 'shape': (8, 1, 2), }", data))), UnsupportedError);
    REQUIRE_THROWS_WITH(readConvdata(test::writeBytes("d.convdata", npy("{'descr': '<f4', 'fortran_order': False, 'shape': (8000, 100, 100), }", data))),
                        Contains("needs 80000000 x 4 bytes"));
}

TEST_CASE("readConvdata: HairNet's blend reads with the counts of SOURCES.md", "[io][data]")
{
    VDBHAIR_REQUIRE_SHARED_DATA();
    const StrandSet s = readConvdata(test::sharedData() + "/hair/hairnet_convdata/strands00014_00035_00010.convdata");
    REQUIRE(s.numStrands() == 940);
    REQUIRE(s.numVertices() == 94000);
}

TEST_CASE("readConvdata: shapes whose product wraps 2^64 or beyond 2^64 are refused by rule", "[io][fuzz]")
{
    const std::string wrap = npy("{'descr': '<f4', 'fortran_order': False, 'shape': (4611686018427387904, 4, 1), }", std::string(64, '\0'));
    REQUIRE_THROWS_WITH(readConvdata(test::writeBytes("wrap.convdata", wrap)),
                        Contains("needs 4611686018427387904 x 4 floats, more than 2^64 bytes"));
    const std::string huge = npy("{'descr': '<f4', 'fortran_order': False, 'shape': (99999999999999999999999, 1, 1), }", std::string(16, '\0'));
    REQUIRE_THROWS_WITH(readConvdata(test::writeBytes("huge.convdata", huge)),
                        Contains("has dimension 99999999999999999999999, beyond 2^64-1"));
}

TEST_CASE("readConvdata: fuzz_convdata's finding, a shape with no strand slots allocates nothing (issue 22)", "[io][fuzz]")
{
    // Shape (8888888888888, 3, 0): no floats, so the file's size bounds nothing, and the reader
    // allocated 2.2e12 points for a strand before it looked at the slots (106 TB requested).
    ReadReport report;
    const StrandSet s = readConvdata(test::regressionInput("fuzz_convdata_zero_slots.convdata"), {}, &report);
    REQUIRE(s.numStrands() == 0);
    REQUIRE(report.warnings.size() == 1);
    REQUIRE_THAT(report.warnings[0], Contains("shape (8888888888888, 3, 0) has no strand slots (rows x columns = 0)"));
}
