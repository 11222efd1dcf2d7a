#include "../TestUtil.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/io/HairFile.h>

#include <cstring>

using namespace vdbhair;
using Catch::Matchers::Contains;

namespace {

/// A cyHair header with the given counts and arrays.
std::string hairHeader(std::uint32_t strands, std::uint32_t points, std::uint32_t arrays, std::uint32_t defSeg = 0)
{
    std::string h = "HAIR";
    test::put(h, strands);
    test::put(h, points);
    test::put(h, arrays);
    test::put(h, defSeg);
    test::put(h, 1.f);
    test::put(h, 0.f);
    for (int i = 0; i < 3; ++i) test::put(h, 0.5f);
    h.append(88, '\0');
    return h;
}

} // namespace

TEST_CASE("readHair/writeHair: every array round-trips exactly", "[io]")
{
    const StrandSet s = test::sampleStrands(true);
    const std::string path = test::tempPath("all.hair");
    writeHair(path, s);
    const StrandSet r = readHair(path);
    test::requireSameStrands(s, r);
    REQUIRE(r.thickness == s.thickness);
    REQUIRE(r.transparency == s.transparency);
    REQUIRE(r.color == s.color);
    // The header says which arrays follow: segments (1), points (2), thickness, transparency, colours.
    const std::string bytes = test::readBytes(path);
    std::uint32_t bits = 0;
    std::memcpy(&bits, bytes.data() + 12, 4);
    REQUIRE(bits == 31u);
}

TEST_CASE("writeHair: equal strand sizes omit the segments array; readHair uses the default", "[io]")
{
    StrandSet s;
    for (int i = 0; i < 4; ++i) s.addStrand(test::helix(1.0 + i, 0.2, 2.0, 6));
    const std::string path = test::tempPath("uniform.hair");
    writeHair(path, s);
    const std::string bytes = test::readBytes(path);
    std::uint32_t bits = 0, defSeg = 0;
    std::memcpy(&bits, bytes.data() + 12, 4);
    std::memcpy(&defSeg, bytes.data() + 16, 4);
    REQUIRE(bits == 2u);
    REQUIRE(defSeg == 5u);
    REQUIRE(bytes.size() == 128 + 24 * 12);
    test::requireSameStrands(s, readHair(path));
}

TEST_CASE("readHair: real files read with the counts of SOURCES.md", "[io][data]")
{
    VDBHAIR_REQUIRE_SHARED_DATA();
    const std::string dir = test::sharedData() + "/hair/cyhair/";
    const StrandSet straight = readHair(dir + "straight.hair");  // no segments array: default 15
    REQUIRE(straight.numStrands() == 10000);
    REQUIRE(straight.numVertices() == 160000);
    REQUIRE(straight.color.size() == 160000);
    const StrandSet bangs = readHair(dir + "Bangs_100.hair");
    REQUIRE(bangs.numStrands() == 100);
    REQUIRE(bangs.numVertices() == 1165);
}

TEST_CASE("readHair: each kind of bad input has its own error", "[io]")
{
    auto pathOf = [](const std::string& name, const std::string& bytes) { return test::writeBytes(name, bytes); };
    std::string pts;
    for (int i = 0; i < 6; ++i) test::put(pts, float(i));

    SECTION("wrong magic")
    {
        std::string b = hairHeader(1, 2, 2, 1) + pts;
        b[0] = 'X';
        REQUIRE_THROWS_WITH(readHair(pathOf("magic.hair", b)), Contains("at byte 0: not a cyHair file"));
    }
    SECTION("shorter than the header")
    {
        REQUIRE_THROWS_WITH(readHair(pathOf("short.hair", "HAIR1234")), Contains("shorter than the 128-byte cyHair header"));
    }
    SECTION("counts the file cannot hold (checked before allocating)")
    {
        const std::string b = hairHeader(1, 0x7fffffff, 2, 1) + pts;
        REQUIRE_THROWS_WITH(readHair(pathOf("huge.hair", b)), Contains("declares 1 strands and 2147483647 points"));
        REQUIRE_THROWS_AS(readHair(pathOf("huge.hair", b)), FormatError);
    }
    SECTION("truncated points array")
    {
        const std::string b = hairHeader(1, 2, 2, 1) + pts.substr(0, 20);
        REQUIRE_THROWS_WITH(readHair(pathOf("trunc.hair", b)), Contains("need 152 bytes, but the file has only 148"));
    }
    SECTION("segments that do not add up to the point count")
    {
        std::string b = hairHeader(1, 2, 3);
        test::put(b, std::uint16_t(4));
        b += pts;
        REQUIRE_THROWS_WITH(readHair(pathOf("segs.hair", b)), Contains("point counts add up to 5 but the header declares 2 points"));
    }
    SECTION("default segments that do not match")
    {
        const std::string b = hairHeader(1, 2, 2, 3) + pts;
        REQUIRE_THROWS_WITH(readHair(pathOf("defseg.hair", b)), Contains("no segments array: every strand has default segments 3 + 1 points"));
    }
    SECTION("unknown array bits and no points array")
    {
        REQUIRE_THROWS_WITH(readHair(pathOf("bits.hair", hairHeader(1, 2, 2 | 64, 1) + pts)), Contains("set unknown bits"));
        REQUIRE_THROWS_WITH(readHair(pathOf("nopts.hair", hairHeader(1, 2, 0, 1))), Contains("no points array"));
    }
    SECTION("a NaN coordinate")
    {
        std::string p2 = pts;
        const float nan = std::nanf("");
        std::memcpy(&p2[16], &nan, 4);
        REQUIRE_THROWS_WITH(readHair(pathOf("nan.hair", hairHeader(1, 2, 2, 1) + p2)),
                            Contains("at byte 140: vertex 1 has a non-finite coordinate"));
    }
    SECTION("a one-point strand is dropped with a warning, or rejected")
    {
        std::string b = hairHeader(2, 3, 3);
        test::put(b, std::uint16_t(0));
        test::put(b, std::uint16_t(1));
        b += pts;
        test::put(b, 6.f); test::put(b, 7.f); test::put(b, 8.f);
        const std::string path = pathOf("one.hair", b);
        ReadReport report;
        const StrandSet s = readHair(path, {}, &report);
        REQUIRE(s.numStrands() == 1);
        REQUIRE(s.root(0) == Vec3f(3.f, 4.f, 5.f));
        REQUIRE(report.droppedStrands == 1);
        REQUIRE_THAT(report.warnings.at(0), Contains("dropped 1 strand(s) with fewer than 2 vertices"));
        ReadOptions strict;
        strict.shortStrands = ShortStrandPolicy::Reject;
        REQUIRE_THROWS_WITH(readHair(path, strict), Contains("strand 0 has 1 vertices; a strand needs at least 2"));
    }
    SECTION("a missing file")
    {
        REQUIRE_THROWS_AS(readHair(test::tempPath("nope.hair")), IoError);
    }
}

TEST_CASE("readHair: strand counts beyond the point count are refused before allocating", "[io][fuzz]")
{
    // 2^32-1 strands of 0 points need no bytes, yet sized 16 GB of counts (issue 22).
    REQUIRE_THROWS_WITH(readHair(test::writeBytes("nS_no_points.hair", hairHeader(0xffffffffu, 0, 2, 0))),
                        Contains("at byte 4: the header declares 4294967295 strands but only 0 points"));
    // Without a segments array every strand has default segments + 1 points.
    std::string pts;
    for (int i = 0; i < 6; ++i) test::put(pts, float(i));
    REQUIRE_THROWS_WITH(readHair(test::writeBytes("nS_default.hair", hairHeader(2, 2, 2, 1) + pts)),
                        Contains("at byte 8: the strands' point counts add up to 4 but the header declares 2 points (no segments array"));
}

TEST_CASE("readHair: fuzz_hair's finding, an absent array copied into an empty set (issue 22)", "[io][fuzz]")
{
    // Zero strands with a thickness array: the copy of 0 values passed a null pointer to memcpy
    // (undefined behaviour under UBSan, HairFile.cc:128). The file reads as an empty set.
    ReadReport report;
    const StrandSet s = readHair(test::regressionInput("fuzz_hair_empty_array.hair"), {}, &report);
    REQUIRE(s.numStrands() == 0);
    REQUIRE(s.positions.empty());
    REQUIRE(report.warnings.size() == 1);
    REQUIRE_THAT(report.warnings[0], Contains("bytes after the arrays the header describes were ignored"));
}
