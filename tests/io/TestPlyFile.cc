#include "../TestUtil.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/io/HairFile.h>
#include <vdbhair/io/PlyFile.h>

#include <cmath>

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
