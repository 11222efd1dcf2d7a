#include "../TestUtil.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/io/HairFile.h>
#include <vdbhair/io/PlyFile.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <random>
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

namespace {

/// @a v in the shortest decimal that reads back the same.
std::string shortFloat(float v)
{
    char buf[32];
    return std::string(buf, std::to_chars(buf, buf + sizeof buf, v).ptr);
}

/// A PLY of @a s's vertices only (as NeuralHaircut and GaussianHaircut write: no topology),
/// written here independently of writePly().
std::string plyPointsOnly(const StrandSet& s, bool binary)
{
    std::string b = std::string("ply\nformat ") + (binary ? "binary_little_endian" : "ascii") + " 1.0\ncomment points in runs\nelement vertex " +
                    std::to_string(s.numVertices()) + "\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
    for (const Vec3f& p : s.positions) {
        if (binary) for (int c = 0; c < 3; ++c) test::put(b, p[c]);
        else b += shortFloat(p.x()) + " " + shortFloat(p.y()) + " " + shortFloat(p.z()) + "\n";
    }
    return b;
}

/// A line set of @a s (Open3D's layout: vertex, then edge with int vertex1, vertex2 and the
/// edge's colour), its edges shuffled and each in a random direction.
std::string plyLineSet(const StrandSet& s, bool binary, std::mt19937& rng)
{
    std::vector<std::pair<std::int32_t, std::int32_t>> edges;
    for (std::size_t i = 0; i < s.numStrands(); ++i)
        for (std::size_t v = s.begin(i); v + 1 < s.end(i); ++v) edges.push_back({std::int32_t(v), std::int32_t(v + 1)});
    std::shuffle(edges.begin(), edges.end(), rng);
    for (auto& e : edges) if (rng() % 2) std::swap(e.first, e.second);
    std::string b = std::string("ply\nformat ") + (binary ? "binary_little_endian" : "ascii") + " 1.0\nelement vertex " +
                    std::to_string(s.numVertices()) + "\nproperty double x\nproperty double y\nproperty double z\nelement edge " +
                    std::to_string(edges.size()) + "\nproperty int vertex1\nproperty int vertex2\nproperty uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n";
    for (const Vec3f& p : s.positions) {
        if (binary) for (int c = 0; c < 3; ++c) test::put(b, double(p[c]));
        else b += shortFloat(p.x()) + " " + shortFloat(p.y()) + " " + shortFloat(p.z()) + "\n";
    }
    for (const auto& [a, c] : edges) {
        if (binary) { test::put(b, a); test::put(b, c); for (int k = 0; k < 3; ++k) test::put(b, std::uint8_t(200)); }
        else b += std::to_string(a) + " " + std::to_string(c) + " 200 200 200\n";
    }
    return b;
}

} // namespace

TEST_CASE("readPly: points in runs of ReadOptions::pointsPerStrand (NeuralHaircut's layout)", "[io][ply-runs]")
{
    // 3 strands of 5 points each.
    StrandSet s;
    for (int i = 0; i < 3; ++i) s.addStrand(test::helix(1.0 + i, 0.2, 3.0, 5));
    ReadOptions runs;
    runs.pointsPerStrand = 5;
    for (bool binary : {true, false}) {
        CAPTURE(binary);
        const std::string path = test::writeBytes("runs.ply", plyPointsOnly(s, binary));
        test::requireSameStrands(s, readPly(path, runs));
        // Without the option: one line that says what to set.
        REQUIRE_THROWS_WITH(readPly(path), Contains("the file has only points: no 'strand' element") &&
                                               Contains("read it with points_per_strand=N"));
        ReadOptions four;
        four.pointsPerStrand = 4;
        REQUIRE_THROWS_WITH(readPly(path, four), Contains("the 'vertex' element has 15 vertices, which is not a multiple of points_per_strand=4"));
        ReadOptions all;
        all.pointsPerStrand = 15;
        REQUIRE(readPly(path, all).numStrands() == 1);
        ReadOptions single;
        single.pointsPerStrand = 1;
        ReadReport report;
        REQUIRE(readPly(path, single, &report).numStrands() == 0);  // one-point strands are dropped, as every reader does
        REQUIRE(report.droppedStrands == 15);
    }
    // A vertex count far beyond the file: refused before anything is allocated.
    std::string huge = "ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
    huge += std::string(24, '\0');
    REQUIRE_THROWS_WITH(readPly(test::writeBytes("runs_huge.ply", huge), runs),
                        Contains("element 'vertex' declares 4000000000 items of at least 12 bytes but only 24 bytes remain"));
    // A file with a strand element keeps its own topology; the option is named in a warning.
    const StrandSet sample = test::sampleStrands(false);
    const std::string hairutil = test::tempPath("runs_hairutil.ply");
    writePly(hairutil, sample);
    ReadReport report;
    test::requireSameStrands(sample, readPly(hairutil, runs, &report));
    REQUIRE(report.warnings.size() == 1);
    REQUIRE_THAT(report.warnings[0], Contains("points_per_strand=5 is ignored"));
}

TEST_CASE("readPly: vertex + edge line sets (Open3D, trimesh) chained into strands", "[io][ply-edges]")
{
    const StrandSet s = test::sampleStrands(false);
    std::mt19937 rng(50);
    for (int trial = 0; trial < 4; ++trial) {
        const bool binary = trial % 2 == 0;
        CAPTURE(trial, binary);
        ReadReport report;
        const StrandSet r = readPly(test::writeBytes("lineset.ply", plyLineSet(s, binary, rng)), {}, &report);
        test::requireSameStrands(s, r, binary ? 0.f : 1e-6f);
        REQUIRE(report.warnings.empty());
    }
    // Roots nearest a point, as for OBJ edges.
    ReadOptions near;
    near.objRootNear = s.tip(0);
    const StrandSet flipped = readPly(test::writeBytes("lineset.ply", plyLineSet(s, true, rng)), near);
    REQUIRE(flipped.root(0) == s.tip(0));
    // The round trip of a hairutil file whose strand element a tool dropped: its edges alone.
    std::string written = test::readBytes([&] { const std::string p = test::tempPath("rt_edges.ply"); writePly(p, s, PlyEncoding::Ascii); return p; }());
    const std::size_t at = written.find("element strand");
    written.erase(at, written.find("element edge") - at);
    const std::size_t body = written.find("end_header\n") + 11;
    std::size_t line = body;
    for (std::size_t v = 0; v < s.numVertices(); ++v) line = written.find('\n', line) + 1;
    std::size_t nsegsEnd = line;
    for (std::size_t i = 0; i < s.numStrands(); ++i) nsegsEnd = written.find('\n', nsegsEnd) + 1;
    written.erase(line, nsegsEnd - line);
    test::requireSameStrands(s, readPly(test::writeBytes("rt_edges.ply", written)), 1e-6f);
}

TEST_CASE("readPly: each kind of bad line set has its own error", "[io][ply-edges]")
{
    const std::string head = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n";
    const std::string verts = "0 0 0\n1 0 0\n2 0 0\n3 0 0\n";
    auto edges = [&](int n, const std::string& body) {
        return head + "element edge " + std::to_string(n) + "\nproperty int vertex1\nproperty int vertex2\nend_header\n" + verts + body;
    };
    REQUIRE(readPly(test::writeBytes("le0.ply", edges(2, "0 1\n2 3\n"))).numStrands() == 2);
    REQUIRE_THROWS_WITH(readPly(test::writeBytes("le1.ply", edges(2, "0 1\n2 4\n"))), Contains("line 16: edge 1 names vertex 4 but the 'vertex' element has 4 (indices are 0-based)"));
    REQUIRE_THROWS_WITH(readPly(test::writeBytes("le2.ply", edges(1, "-1 2\n"))), Contains("edge 0 names vertex -1"));
    REQUIRE_THROWS_WITH(readPly(test::writeBytes("le3.ply", edges(3, "0 1\n1 2\n3 1\n"))),
                        Contains("vertex 1 joins 3 or more others (edges 0, 1 and 2); a strand cannot branch"));
    REQUIRE_THROWS_WITH(readPly(test::writeBytes("le4.ply", edges(3, "0 1\n1 2\n2 0\n"))), Contains("vertex 0 lies on a closed loop of edges (edge 0)"));
    REQUIRE_THROWS_WITH(readPly(test::writeBytes("le5.ply", head + "element edge 1\nproperty int a\nproperty int b\nend_header\n" + verts + "0 1\n")),
                        Contains("the 'edge' element needs scalar properties vertex1 and vertex2"));
    REQUIRE_THROWS_WITH(readPly(test::writeBytes("le6.ply", edges(1, "2 2\n"))), Contains("the 'edge' element joins no two vertices"));
    ReadReport report;
    REQUIRE(readPly(test::writeBytes("le7.ply", edges(2, "0 1\n1 0\n")), {}, &report).numStrands() == 1);
    REQUIRE(report.warnings.size() == 2);
    REQUIRE_THAT(report.warnings[0], Contains("ignored 1 repeated edge(s)"));
    REQUIRE_THAT(report.warnings[1], Contains("2 of 4 vertices are on no edge and were ignored"));
    // An edge count far beyond the file (binary): refused before anything is allocated.
    std::string huge = "ply\nformat binary_little_endian 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\n"
                       "element edge 4000000000\nproperty int vertex1\nproperty int vertex2\nend_header\n";
    for (float f : {0.f, 0.f, 0.f, 1.f, 1.f, 1.f}) test::put(huge, f);
    test::put(huge, std::int32_t(0));
    test::put(huge, std::int32_t(1));
    REQUIRE_THROWS_WITH(readPly(test::writeBytes("le_huge.ply", huge)), Contains("element 'edge' declares 4000000000 items of at least 8 bytes but only 8 bytes remain"));
    huge.replace(huge.find("4000000000"), 10, "1");
    REQUIRE(readPly(test::writeBytes("le_one.ply", huge)).numStrands() == 1);
}
