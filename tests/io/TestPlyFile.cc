#include "../TestUtil.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/io/HairFile.h>
#include <vdbhair/io/PlyFile.h>

#include <cmath>
#include <cstring>
#include <limits>

using namespace vdbhair;
using Catch::Matchers::Contains;

TEST_CASE("readPly/writePly: binary and ASCII round-trip positions; colours to 8 bits", "[io]")
{
    StrandSet s = test::sampleStrands(true);
    for (PlyEncoding enc : {PlyEncoding::Binary, PlyEncoding::Ascii}) {
        const std::string path = test::tempPath(enc == PlyEncoding::Binary ? "rt_bin.ply" : "rt_ascii.ply");
        writePly(path, s, enc);
        const StrandSet r = readPly(path);
        test::requireSameStrands(s, r);
        REQUIRE(r.color.size() == s.color.size());
        for (std::size_t v = 0; v < s.numVertices(); ++v) {
            for (int c = 0; c < 3; ++c) REQUIRE(std::abs(r.color[v][c] - s.color[v][c]) <= 0.5f / 255.f + 1e-6f);
        }
    }
}

TEST_CASE("readPly: hairutil's Bangs_100 in ASCII and binary equals the cyHair file", "[io][data]")
{
    VDBHAIR_REQUIRE_SHARED_DATA();
    const std::string dir = test::sharedData() + "/hair/";
    const StrandSet hair = readHair(dir + "cyhair/Bangs_100.hair");
    const StrandSet bin = readPly(dir + "ply/Bangs_100_binary.ply");
    const StrandSet ascii = readPly(dir + "ply/Bangs_100_ascii.ply");
    REQUIRE(bin.numVertices() == 1165);
    test::requireSameStrands(hair, bin);
    test::requireSameStrands(hair, ascii, 1e-3f);  // ASCII prints 6 decimals
    const StrandSet curly = readPly(dir + "ply/Curly_100.ply");
    REQUIRE(curly.numStrands() == 100);
    REQUIRE(curly.numVertices() == 2528);
}

TEST_CASE("readPly: each kind of bad input has its own error", "[io]")
{
    const std::string head = "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\n";
    const std::string strand = "element strand 1\nproperty ushort nsegs\nend_header\n";
    REQUIRE(readPly(test::writeBytes("ok.ply", head + strand + "0 0 0\n1 1 1\n1\n")).numVertices() == 2);

    REQUIRE_THROWS_WITH(readPly(test::writeBytes("p1.ply", "plx\n")), Contains("line 1: not a PLY file"));
    REQUIRE_THROWS_WITH(readPly(test::writeBytes("p2.ply", head + "end_header\n0 0 0\n1 1 1\n")), Contains("no 'strand' element"));
    REQUIRE_THROWS_WITH(readPly(test::writeBytes("p3.ply", head + strand + "0 0 0\n1 1 1\n3\n")),
                        Contains("nsegs + 1 add up to 4 vertices but the 'vertex' element has 2"));
    REQUIRE_THROWS_AS(readPly(test::writeBytes("p4.ply", "ply\nformat binary_big_endian 1.0\nend_header\n")), UnsupportedError);
    REQUIRE_THROWS_WITH(readPly(test::writeBytes("p5.ply", head + strand + "0 0 0 1 1 1\n\n\n")), Contains("file ends before nsegs"));
    REQUIRE_THROWS_WITH(readPly(test::writeBytes("p5b.ply", head + strand + "0 0 0\n1 1\n")), Contains("element 'vertex' declares 2 items of at least 6 bytes but only 10 bytes remain"));
    REQUIRE_THROWS_WITH(readPly(test::writeBytes("p6.ply", "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\n" + strand)),
                        Contains("needs scalar properties x, y and z"));
    REQUIRE_THROWS_WITH(readPly(test::writeBytes("p7.ply", head + strand)), Contains("element 'vertex' declares 2 items"));
    REQUIRE_THROWS_WITH(readPly(test::writeBytes("p8.ply", head)), Contains("no 'end_header'"));
    // A binary vertex count far beyond the file: refused before anything is allocated.
    const std::string binHead = "ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\nproperty float x\n"
                                "property float y\nproperty float z\n" + strand;
    REQUIRE_THROWS_WITH(readPly(test::writeBytes("p9.ply", binHead + std::string(30, '\0'))),
                        Contains("element 'vertex' declares 4000000000 items of at least 12 bytes but only 30 bytes remain"));
    REQUIRE_THROWS_WITH(readPly(test::writeBytes("p10.ply", head + strand + "0 0 0\n1 inf 1\n1\n")), Contains("vertex 1 has a non-finite coordinate"));
}

TEST_CASE("readPly: property-less elements and nsegs sums beyond the vertices (issue 22)", "[io][fuzz]")
{
    const std::string vertex = "element vertex 2\nproperty float x\nproperty float y\nproperty float z\n";
    SECTION("an element of 2^63-1 items without properties holds no bytes and is skipped at once")
    {
        std::string b = "ply\nformat binary_little_endian 1.0\nelement junk 9223372036854775807\n" + vertex +
                        "element strand 1\nproperty ushort nsegs\nend_header\n";
        for (float f : {0.f, 0.f, 0.f, 1.f, 1.f, 1.f}) test::put(b, f);
        test::put(b, std::uint16_t(1));
        REQUIRE(readPly(test::writeBytes("junk.ply", b)).numVertices() == 2);
    }
    SECTION("nsegs whose sum + 1 wraps 2^64 back to the vertex count")
    {
        const std::string b = "ply\nformat ascii 1.0\n" + vertex + "element strand 2\nproperty double nsegs\nend_header\n"
                              "0 0 0\n1 1 1\n9223372036854775808\n9223372036854775808\n";
        REQUIRE_THROWS_WITH(readPly(test::writeBytes("wrap.ply", b)),
                            Contains("the strands' nsegs + 1 add up to more than 2^64-1 vertices but the 'vertex' element has 2"));
    }
}

TEST_CASE("readPly: binary files are read in place with the generic reader's strands and errors", "[io]")
{
    // Three strands (2, 1 and 3 vertices) with 8-bit colours; the middle one is dropped by default.
    const std::vector<Vec3f> pts{{0, 0, 0}, {1, 0, 0}, {5, 5, 5}, {0, 1, 0}, {0, 2, 0}, {0, 3, 0}};
    const std::vector<std::uint16_t> nsegs{1, 0, 2};
    auto header = [](const char* format, const char* coord, bool list) {
        std::string h = std::string("ply\nformat ") + format + " 1.0\nelement vertex 6\n";
        for (const char* c : {"x", "y", "z"}) h += std::string("property ") + coord + " " + c + "\n";
        h += "property uchar red\nproperty uchar green\nproperty uchar blue\nelement strand 3\nproperty ushort nsegs\n";
        if (list) h += "element face 1\nproperty list uchar int vertex_indices\n";
        return h + "end_header\n";
    };
    auto binary = [&](bool asDouble, bool list) {
        std::string b = header("binary_little_endian", asDouble ? "double" : "float", list);
        for (std::size_t v = 0; v < pts.size(); ++v) {
            for (int c = 0; c < 3; ++c) asDouble ? test::put(b, double(pts[v][c])) : test::put(b, pts[v][c]);
            for (int c = 0; c < 3; ++c) test::put(b, std::uint8_t(40 * v + c));
        }
        for (std::uint16_t n : nsegs) test::put(b, n);
        if (list) { test::put(b, std::uint8_t(3)); for (int i = 0; i < 3; ++i) test::put(b, std::int32_t(i)); }
        return b;
    };
    std::string ascii = header("ascii", "float", false);
    for (std::size_t v = 0; v < pts.size(); ++v) {
        ascii += std::to_string(pts[v][0]) + " " + std::to_string(pts[v][1]) + " " + std::to_string(pts[v][2]);
        for (int c = 0; c < 3; ++c) ascii += " " + std::to_string(40 * v + c);
        ascii += "\n";
    }
    for (std::uint16_t n : nsegs) ascii += std::to_string(n) + "\n";

    ReadReport generic;
    const StrandSet expected = readPly(test::writeBytes("gen.ply", ascii), {}, &generic);
    REQUIRE(expected.numStrands() == 2);
    REQUIRE(generic.droppedStrands == 1);
    REQUIRE(expected.color[2][0] == Approx(120.f / 255.f));  // the third strand's root, after the dropped one
    for (bool asDouble : {false, true}) {
        for (bool list : {false, true}) {  // a list property takes the generic path
            CAPTURE(asDouble, list);
            ReadReport report;
            const StrandSet s = readPly(test::writeBytes("inplace.ply", binary(asDouble, list)), {}, &report);
            test::requireSameStrands(expected, s);
            REQUIRE(s.color == expected.color);
            REQUIRE(report.droppedStrands == 1);
            ReadOptions strict;
            strict.shortStrands = ShortStrandPolicy::Reject;
            REQUIRE_THROWS_WITH(readPly(test::writeBytes("inplace.ply", binary(asDouble, list)), strict),
                                Contains("vertex 2: strand 1 has 1 vertices"));
        }
    }
    // A non-finite coordinate is named with the byte after its vertex, as the generic reader does.
    std::string bad = binary(false, false);
    const std::size_t body = header("binary_little_endian", "float", false).size();
    const float inf = std::numeric_limits<float>::infinity();
    std::memcpy(&bad[body + 15 + 4], &inf, 4);  // vertex 1's y (15 bytes a vertex)
    const std::string expectedAt = "at byte " + std::to_string(body + 30) + ": vertex 1 has a non-finite coordinate";
    REQUIRE_THROWS_WITH(readPly(test::writeBytes("inf.ply", bad)), Contains(expectedAt));
    std::string badList = binary(false, true);
    std::memcpy(&badList[body + std::string("element face 1\nproperty list uchar int vertex_indices\n").size() + 15 + 4], &inf, 4);
    REQUIRE_THROWS_WITH(readPly(test::writeBytes("inf_list.ply", badList)), Contains(": vertex 1 has a non-finite coordinate"));
    // A fractional nsegs (float property) fails at the byte after its item.
    std::string frac = header("binary_little_endian", "float", false);
    frac.replace(frac.find("property ushort nsegs"), 21, "property float nsegs");
    for (std::size_t v = 0; v < pts.size(); ++v) {
        for (int c = 0; c < 3; ++c) test::put(frac, pts[v][c]);
        for (int c = 0; c < 3; ++c) test::put(frac, std::uint8_t(0));
    }
    for (float n : {1.f, 0.5f, 2.f}) test::put(frac, n);
    REQUIRE_THROWS_WITH(readPly(test::writeBytes("frac.ply", frac)),
                        Contains("at byte " + std::to_string(frac.size() - 4) + ": strand 1 has nsegs 0.500000; it must be a non-negative integer"));
}
