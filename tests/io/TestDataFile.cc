#include "../TestUtil.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/io/BinFile.h>
#include <vdbhair/io/DataFile.h>
#include <vdbhair/io/HairFile.h>

#include <tbb/task_arena.h>

#include <cstring>
#include <limits>
#include <string>
#include <vector>

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

namespace {

/// A .data file of @a counts strands: strand i's vertex j at (i, j, i * j), with a NaN at vertex
/// @a nanVertex of strand @a nanStrand (-1: none); a count of @a lie replaces strand @a lieStrand's
/// (-1: none) without changing what follows.
std::string dataBytes(const std::vector<int>& counts, int nanStrand = -1, int nanVertex = 0, int lieStrand = -1, int lie = 0)
{
    std::string b;
    test::put(b, std::int32_t(counts.size()));
    for (int i = 0; i < int(counts.size()); ++i) {
        test::put(b, std::int32_t(i == lieStrand ? lie : counts[std::size_t(i)]));
        for (int j = 0; j < counts[std::size_t(i)]; ++j) {
            test::put(b, float(i));
            test::put(b, i == nanStrand && j == nanVertex ? std::numeric_limits<float>::quiet_NaN() : float(j));
            test::put(b, float(i * j) * 0.5f);
        }
    }
    return b;
}

/// The message of what @a fn throws ("" if nothing).
template<typename Fn>
std::string thrown(Fn&& fn)
{
    try {
        fn();
    } catch (const std::exception& e) {
        return e.what();
    }
    return "";
}

void requireSameSummary(const StrandSummary& a, const StrandSummary& b)
{
    REQUIRE(a.strands == b.strands);
    REQUIRE(a.vertices == b.vertices);
    REQUIRE(a.bbox.min == b.bbox.min);
    REQUIRE(a.bbox.max == b.bbox.max);
    REQUIRE(a.length.min == b.length.min);
    REQUIRE(a.length.mean == b.length.mean);
    REQUIRE(a.length.max == b.length.max);
    REQUIRE(a.verticesPerStrand.min == b.verticesPerStrand.min);
    REQUIRE(a.verticesPerStrand.mean == b.verticesPerStrand.mean);
    REQUIRE(a.verticesPerStrand.max == b.verticesPerStrand.max);
}

} // namespace

TEST_CASE("summarizeData: the summary, warnings and first error of reading the file, without its strands", "[io]")
{
    // 700 strands of 0 to 9 vertices (the 140 short ones dropped, with a warning), and 5 bytes more.
    std::vector<int> counts;
    for (int i = 0; i < 700; ++i) counts.push_back((i * 7 + 1) % 10);
    const std::string path = test::writeBytes("summary.data", dataBytes(counts) + "extra");
    ReadReport r1, r2;
    const StrandSummary read = summarizeStrands(readData(path, {}, &r1));
    const StrandSummary measured = summarizeData(path, {}, &r2);
    requireSameSummary(read, measured);
    REQUIRE(read.strands == 560);
    REQUIRE(r1.warnings == r2.warnings);
    REQUIRE(r1.warnings.size() == 2);
    REQUIRE(r1.droppedStrands == r2.droppedStrands);
    // The same on one thread.
    tbb::task_arena one(1);
    one.execute([&] { requireSameSummary(read, summarizeData(path)); });
    // readData() copies the strands in parallel: the same set on one thread, vertex for vertex.
    const StrandSet all = readData(path);
    REQUIRE(all.numVertices() > 0);
    one.execute([&] {
        const StrandSet serial = readData(path);
        REQUIRE(serial.offsets == all.offsets);
        REQUIRE(serial.positions == all.positions);
    });
    // File strand i has vertex j at (i, j, i j / 2); file strand 0 (1 vertex) is dropped, so kept strand 0 is file strand 1.
    REQUIRE(all.data(0)[3] == Vec3f(1.f, 3.f, 1.5f));
    REQUIRE(all.data(1)[3] == Vec3f(2.f, 3.f, 3.f));

    // Whichever fault comes first in the file is the one reported, by both.
    ReadOptions strict;
    strict.shortStrands = ShortStrandPolicy::Reject;
    struct Fault { const char* what; std::string bytes; ReadOptions opts; const char* expect; };
    const std::vector<Fault> faults = {
        {"a NaN before a lying count", dataBytes(counts, 12, 3, 40, 1 << 30), {}, "vertex"},
        {"a lying count before a NaN", dataBytes(counts, 41, 3, 12, 1 << 30), {}, "declares 1073741824 vertices"},
        {"a NaN in a strand dropped as short", dataBytes(counts, 0, 0), {}, "non-finite"},
        {"a short strand refused before a NaN", dataBytes(counts, 12, 3), strict, "has 1 vertices"},
        {"a NaN in the strand refused as short", dataBytes(counts, 0, 0), strict, "non-finite"},
        {"a negative count", dataBytes(counts, -1, 0, 5, -2), {}, "counts must not be negative"},
    };
    for (const Fault& f : faults) {
        const std::string p = test::writeBytes("fault.data", f.bytes);
        const std::string a = thrown([&] { readData(p, f.opts); }), b = thrown([&] { summarizeData(p, f.opts); });
        CAPTURE(f.what, a, b);
        REQUIRE(!a.empty());
        REQUIRE(a.find(f.expect) != std::string::npos);
        REQUIRE(a == b);
    }
}

TEST_CASE("summarizeData: real files give the summary of reading them", "[io][data]")
{
    VDBHAIR_REQUIRE_SHARED_DATA();
    for (const char* name : {"harolongo.data", "Bangs_100.data", "hairnet_cstrands/cstrands00001.data"}) {
        const std::string path = test::sharedData() + "/hair/usc_data/" + name;
        CAPTURE(path);
        requireSameSummary(summarizeStrands(readData(path)), summarizeData(path));
    }
}
