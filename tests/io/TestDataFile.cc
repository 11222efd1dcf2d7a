#include "../TestUtil.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/io/BinFile.h>
#include <vdbhair/io/DataFile.h>
#include <vdbhair/io/HairFile.h>

#include <cstring>
#include <limits>

using namespace vdbhair;
using Catch::Matchers::Contains;

TEST_CASE("readData/writeData: positions round-trip exactly", "[io]")
{
    const StrandSet s = test::sampleStrands(false);
    const std::string path = test::tempPath("rt.data");
    writeData(path, s);
    REQUIRE(test::readBytes(path).size() == 4 + 3 * 4 + 12 * s.numVertices());
    test::requireSameStrands(s, readData(path));
}

TEST_CASE("readData: real files read with the counts of SOURCES.md", "[io][data]")
{
    VDBHAIR_REQUIRE_SHARED_DATA();
    const std::string dir = test::sharedData() + "/hair/usc_data/";
    const StrandSet harolongo = readData(dir + "harolongo.data");
    REQUIRE(harolongo.numStrands() == 7905);
    REQUIRE(harolongo.numVertices() == 166005);
    const StrandSet c = readData(dir + "hairnet_cstrands/cstrands00001.data");
    REQUIRE(c.numStrands() == 5);
    REQUIRE(c.numVertices() == 500);
}

TEST_CASE("readBin: CT2Hair's Bangs_100 equals the cyHair and USC versions", "[io][data]")
{
    VDBHAIR_REQUIRE_SHARED_DATA();
    const std::string dir = test::sharedData() + "/hair/";
    const StrandSet bin = readBin(dir + "ct2hair_bin/Bangs_100.bin");
    REQUIRE(bin.numStrands() == 100);
    REQUIRE(bin.numVertices() == 1165);
    test::requireSameStrands(bin, readHair(dir + "cyhair/Bangs_100.hair"));
    test::requireSameStrands(bin, readData(dir + "usc_data/Bangs_100.data"));
}

TEST_CASE("readData / readBin: each kind of bad input has its own error", "[io]")
{
    std::string ok;
    test::put(ok, std::int32_t(1));
    test::put(ok, std::int32_t(2));
    for (int i = 0; i < 6; ++i) test::put(ok, float(i));
    REQUIRE(readData(test::writeBytes("ok.data", ok)).numVertices() == 2);

    SECTION("negative strand count")
    {
        std::string b;
        test::put(b, std::int32_t(-3));
        REQUIRE_THROWS_WITH(readData(test::writeBytes("neg.data", b)), Contains("at byte 0: strand count -3 is negative"));
    }
    SECTION("a strand count the file cannot hold")
    {
        std::string b;
        test::put(b, std::int32_t(2000000000));
        REQUIRE_THROWS_WITH(readData(test::writeBytes("many.data", b)), Contains("the declared 2000000000 strands needs"));
    }
    SECTION("a vertex count the file cannot hold")
    {
        std::string b = ok;
        std::int32_t big = 70000;
        std::memcpy(&b[4], &big, 4);
        REQUIRE_THROWS_WITH(readData(test::writeBytes("verts.data", b)),
                            Contains("at byte 4: strand 0 declares 70000 vertices (840000 bytes) but only 24 bytes remain"));
    }
    SECTION("negative vertex count")
    {
        std::string b = ok;
        std::int32_t neg = -1;
        std::memcpy(&b[4], &neg, 4);
        REQUIRE_THROWS_WITH(readData(test::writeBytes("negv.data", b)), Contains("declares -1 vertices; counts must not be negative"));
    }
    SECTION("truncated file")
    {
        REQUIRE_THROWS_WITH(readData(test::writeBytes("trunc.data", ok.substr(0, 2))), Contains("strand count needs 1 x 4 bytes but only 2 remain"));
    }
    SECTION("infinite coordinate")
    {
        std::string b = ok;
        const float inf = INFINITY;
        std::memcpy(&b[8 + 4], &inf, 4);
        REQUIRE_THROWS_WITH(readData(test::writeBytes("inf.data", b)), Contains("at byte 8: vertex 0 has a non-finite coordinate"));
    }
    SECTION("short strands: dropped with a warning, or rejected")
    {
        std::string b;
        test::put(b, std::int32_t(3));
        test::put(b, std::int32_t(0));
        test::put(b, std::int32_t(1));
        for (int i = 0; i < 3; ++i) test::put(b, 9.f);
        b += ok.substr(4);
        const std::string path = test::writeBytes("shortstr.data", b);
        ReadReport report;
        const StrandSet s = readData(path, {}, &report);
        REQUIRE(s.numStrands() == 1);
        REQUIRE(s.root(0) == Vec3f(0.f, 1.f, 2.f));
        REQUIRE(report.droppedStrands == 2);
        ReadOptions strict;
        strict.shortStrands = ShortStrandPolicy::Reject;
        REQUIRE_THROWS_WITH(readData(path, strict), Contains("at byte 4: strand 0 has 0 vertices"));
    }
    SECTION("bin: a vertex count the file cannot hold")
    {
        std::string b;
        test::put(b, std::int32_t(1));
        test::put(b, std::int32_t(5));
        for (int i = 0; i < 7; ++i) test::put(b, 0.f);
        REQUIRE_THROWS_WITH(readBin(test::writeBytes("b.bin", b)), Contains("strand 0 declares 5 vertices (140 bytes) but only 28 bytes remain"));
    }
    SECTION("bin: a non-finite coordinate is named with its vertex's byte")
    {
        std::string b;
        test::put(b, std::int32_t(1));
        test::put(b, std::int32_t(3));
        for (int v = 0; v < 3; ++v) {
            for (int i = 0; i < 7; ++i) test::put(b, v == 1 && i == 2 ? std::numeric_limits<float>::quiet_NaN() : float(v));
        }
        REQUIRE_THROWS_WITH(readBin(test::writeBytes("nan.bin", b)), Contains("at byte 36: vertex 1 has a non-finite coordinate"));
    }
}
