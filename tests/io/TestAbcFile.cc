#include "../TestUtil.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/io/AbcFile.h>
#include <vdbhair/io/Ogawa.h>
#include <vdbhair/io/StrandIO.h>

#include <cstring>
#include <random>

using namespace vdbhair;
using Catch::Matchers::Contains;

namespace {

std::uint64_t word(const std::string& bytes, std::uint64_t at)
{
    std::uint64_t v;
    std::memcpy(&v, bytes.data() + at, 8);
    return v;
}
void setWord(std::string& bytes, std::uint64_t at, std::uint64_t v) { std::memcpy(&bytes[at], &v, 8); }

// ---- a hand-built archive, for what vdbhair's writer does not make (cubic curves, several
// objects, an Xform parent, animation): AbcCoreOgawa's encoding with 4-byte fields (size hint 2)
// and inline metadata (index 255), both legal and not what writeAbc uses.

struct TestProperty
{
    std::string name, md;
    unsigned type = 2, pod = 10, extent = 1;  // array of float32
    std::vector<std::string> samples;          // raw bytes of each sample
};

void push32(std::string& s, std::uint32_t v) { s.append(reinterpret_cast<const char*>(&v), 4); }

template<typename T>
std::string bytesOf(const std::vector<T>& v) { return std::string(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T)); }

std::string propertyHeaders(const std::vector<TestProperty>& props)
{
    std::string out;
    for (const TestProperty& p : props) {
        const std::uint32_t n = std::uint32_t(p.samples.size());
        std::uint32_t info = (2u << 2) | (255u << 20) | p.type;
        if (p.type != 0) info |= (p.pod << 4) | (p.extent << 12) | (n == 1 ? 0x800u : 0u);
        push32(out, info);
        if (p.type != 0) push32(out, n);
        push32(out, std::uint32_t(p.name.size()));
        out += p.name;
        push32(out, std::uint32_t(p.md.size()));
        out += p.md;
    }
    return out;
}

ogawa::Writer::Node propertyGroup(ogawa::Writer& w, const TestProperty& p)
{
    std::vector<ogawa::Writer::Node> children;
    for (const std::string& s : p.samples) {
        children.push_back(w.addData(std::string(16, '\0') + s));
        if (p.type == 2) children.push_back(w.addData(std::string()));
    }
    return w.addGroup(children);
}

struct TestCurves
{
    std::string name;
    std::vector<Vec3f> points;
    std::vector<std::int32_t> counts;
    std::vector<std::uint8_t> basisAndType{1, 0, 0, 0};
    std::vector<float> widths;
    std::string widthScope = "vtx";
    int frames = 1;  // frames > 1: P gets that many samples (each moved by +1 in x)
    std::vector<std::uint32_t> widthIndices;  // not empty: width is indexed (.vals and .indices)
};

std::string buildArchive(const std::vector<TestCurves>& objects, bool underXform,
                         const std::vector<std::uint8_t>& ops = {}, const std::vector<double>& vals = {})
{
    ogawa::Writer w;
    std::vector<ogawa::Writer::Node> objectGroups;
    std::string childHeaders;
    for (const TestCurves& c : objects) {
        std::vector<TestProperty> props;
        TestProperty P{"P", "geoScope=vtx;interpretation=point", 2, 10, 3, {}};
        for (int f = 0; f < c.frames; ++f) {
            std::vector<Vec3f> moved = c.points;
            for (Vec3f& p : moved) p.x() += float(f);
            P.samples.push_back(bytesOf(moved));
        }
        props.push_back(P);
        props.push_back({"nVertices", "", 2, 6, 1, {bytesOf(c.counts)}});
        props.push_back({"curveBasisAndType", "", 1, 1, 4, {bytesOf(c.basisAndType)}});
        const std::string widthMd = "geoScope=" + c.widthScope + ";isGeomParam=true";
        if (!c.widths.empty() && c.widthIndices.empty()) props.push_back({"width", widthMd, 2, 10, 1, {bytesOf(c.widths)}});
        std::vector<ogawa::Writer::Node> geomChildren;
        for (const TestProperty& p : props) geomChildren.push_back(propertyGroup(w, p));
        if (!c.widthIndices.empty()) {  // an indexed parameter: a compound of .vals and .indices
            const std::vector<TestProperty> sub{{".vals", widthMd, 2, 10, 1, {bytesOf(c.widths)}},
                                                {".indices", "", 2, 5, 1, {bytesOf(c.widthIndices)}}};
            geomChildren.push_back(w.addGroup({propertyGroup(w, sub[0]), propertyGroup(w, sub[1]), w.addData(propertyHeaders(sub))}));
            props.push_back({"width", widthMd, 0, 0, 0, {}});
        }
        geomChildren.push_back(w.addData(propertyHeaders(props)));
        const auto geom = w.addGroup(geomChildren);
        const auto objProps = w.addGroup({geom, w.addData(propertyHeaders({{".geom", "schema=AbcGeom_Curve_v2", 0, 0, 0, {}}}))});
        objectGroups.push_back(w.addGroup({objProps, w.addData(std::string(32, '\0'))}));
        const std::string md = "schema=AbcGeom_Curve_v2;schemaObjTitle=AbcGeom_Curve_v2:.geom";
        push32(childHeaders, std::uint32_t(c.name.size()));
        childHeaders += c.name;
        childHeaders += char(255);
        push32(childHeaders, std::uint32_t(md.size()));
        childHeaders += md;
    }
    childHeaders += std::string(32, '\0');
    // The parent's properties: none, or (under an Xform with operations) .xform with .ops and
    // .vals as scalars, as OXform writes a static transform.
    ogawa::Writer::Node parentProps = w.addGroup({});
    if (underXform && !ops.empty()) {
        const std::vector<TestProperty> fields{{".ops", "", 1, 1, unsigned(ops.size()), {bytesOf(ops)}},
                                               {".vals", "", 1, 11, unsigned(vals.size()), {bytesOf(vals)}}};
        const auto xform = w.addGroup({propertyGroup(w, fields[0]), propertyGroup(w, fields[1]), w.addData(propertyHeaders(fields))});
        parentProps = w.addGroup({xform, w.addData(propertyHeaders({{".xform", "schema=AbcGeom_Xform_v3", 0, 0, 0, {}}}))});
    }
    std::vector<ogawa::Writer::Node> parentChildren{parentProps};
    parentChildren.insert(parentChildren.end(), objectGroups.begin(), objectGroups.end());
    parentChildren.push_back(w.addData(childHeaders));
    ogawa::Writer::Node top = w.addGroup(parentChildren);
    if (underXform) {
        std::string headers;
        const std::string md = "schema=AbcGeom_Xform_v3;schemaObjTitle=AbcGeom_Xform_v3:.xform";
        push32(headers, 5);
        headers += "groom";
        headers += char(255);
        push32(headers, std::uint32_t(md.size()));
        headers += md;
        headers += std::string(32, '\0');
        top = w.addGroup({w.addGroup({}), top, w.addData(headers)});
    }
    std::string version(4, '\0'), library(4, '\0');
    const std::int32_t lib = 10812;
    std::memcpy(&library[0], &lib, 4);
    w.addGroup({w.addData(version), w.addData(library), top, w.addData(std::string("_ai_AlembicVersion=test")),
                w.addData(std::string()), w.addData(std::string())});
    std::string file;
    w.write([&](const void* d, std::uint64_t n) { file.append(static_cast<const char*>(d), std::size_t(n)); });
    return file;
}

} // namespace

TEST_CASE("murmur3x64_128: the digests the reference Alembic library stored", "[io][abc]")
{
    // From a file written by Alembic 1.8.12: nVertices {2, 3, 4} and curveBasisAndType {1, 0, 1, 1}.
    const std::int32_t counts[3] = {2, 3, 4};
    const std::uint8_t basis[4] = {1, 0, 1, 1};
    std::uint64_t d[2];
    ogawa::murmur3x64_128(counts, sizeof(counts), d);
    unsigned char bytes[16];
    std::memcpy(bytes, d, 16);
    char hex[33];
    for (int i = 0; i < 16; ++i) std::snprintf(hex + 2 * i, 3, "%02x", bytes[i]);
    REQUIRE(std::string(hex) == "6e094048738c98eefde5cc3260e07fc2");
    ogawa::murmur3x64_128(basis, sizeof(basis), d);
    std::memcpy(bytes, d, 16);
    for (int i = 0; i < 16; ++i) std::snprintf(hex + 2 * i, 3, "%02x", bytes[i]);
    REQUIRE(std::string(hex) == "2b062640406f998d7f6e446a12199c6c");
}

TEST_CASE("writeAbc/readAbc: positions, widths, colours, root UVs and ids round-trip exactly", "[io][abc]")
{
    StrandSet s = test::sampleStrands(true);
    REQUIRE(!s.color.empty());
    for (std::size_t i = 0; i < s.numStrands(); ++i) s.rootUV.emplace_back(0.25f * float(i), 1.f - 0.125f * float(i));
    for (std::size_t i = 0; i < s.numStrands(); ++i) s.strandId.push_back(std::int32_t(100 + 7 * i));
    const std::string path = test::tempPath("rt.abc");
    writeAbc(path, s);
    ReadReport report;
    const StrandSet r = readAbc(path, {}, &report);
    test::requireSameStrands(s, r);
    REQUIRE(r.positions == s.positions);
    REQUIRE(r.thickness == s.thickness);
    REQUIRE(r.rootUV == s.rootUV);
    REQUIRE(r.color == s.color);        // .arbGeomParams/Cd
    REQUIRE(r.strandId == s.strandId);  // .arbGeomParams/groom_id
    REQUIRE(report.warnings.empty());
    // Unreal's groom attributes are written beside width and uv.
    const std::string bytes = test::readBytes(path);
    REQUIRE(bytes.find("groom_root_uv") != std::string::npos);
    REQUIRE(bytes.find("groom_width") != std::string::npos);
    // Through the format table too, and the same bytes every time (no date, no pointers).
    writeStrands(test::tempPath("rt2.abc"), s);
    REQUIRE(test::readBytes(test::tempPath("rt2.abc")) == test::readBytes(path));
    REQUIRE(readStrands(test::tempPath("rt2.abc")).positions == s.positions);
}

TEST_CASE("writeAbc/readAbc: seeded random sets across scales round-trip bit for bit", "[io][abc]")
{
    for (int seed = 0; seed < 8; ++seed) {
        CAPTURE(seed);
        std::mt19937 rng(seed);
        std::uniform_real_distribution<float> u(-1.f, 1.f);
        const float scale = std::pow(10.f, float(seed - 4));
        StrandSet s;
        const int strands = 1 + seed * 37;
        for (int i = 0; i < strands; ++i) {
            std::vector<Vec3f> p(2 + std::size_t(rng() % 40));
            for (Vec3f& q : p) q = Vec3f(u(rng), u(rng), u(rng)) * scale;
            s.addStrand(p);
        }
        s.defaults.thickness = 0.5f * scale;
        const std::string path = test::tempPath("random.abc");
        writeAbc(path, s);
        const StrandSet r = readAbc(path);
        REQUIRE(r.offsets == s.offsets);
        REQUIRE(r.positions == s.positions);
        REQUIRE(r.thickness.empty());
        REQUIRE(r.defaults.thickness == s.defaults.thickness);  // one constant width
    }
}

TEST_CASE("writeAbc: the layout of the reference library's Curves", "[io][abc]")
{
    StrandSet s = test::sampleStrands(true);
    const std::string path = test::tempPath("layout.abc");
    writeAbc(path, s);
    const std::string bytes = test::readBytes(path);
    REQUIRE(bytes.compare(0, 5, "Ogawa") == 0);
    REQUIRE(static_cast<unsigned char>(bytes[5]) == 0xff);
    REQUIRE(bytes[6] == 0);
    REQUIRE(bytes[7] == 1);
    ogawa::Reader r(bytes.data(), bytes.size(), "layout");
    const auto root = r.group(r.rootPos(), "root");
    REQUIRE(root.children.size() == 6);
    const auto version = r.childData(root, 0, "version");
    const auto library = r.childData(root, 1, "library");
    REQUIRE(version.size == 4);
    REQUIRE(library.size == 4);
    std::int32_t v[2];
    std::memcpy(&v[0], version.bytes, 4);
    std::memcpy(&v[1], library.bytes, 4);
    REQUIRE(v[0] == 0);
    REQUIRE(v[1] == 10812);
    const auto md = r.childData(root, 3, "metadata");
    const std::string archiveMd(md.bytes, md.size);
    REQUIRE_THAT(archiveMd, Contains("_ai_AlembicVersion=Alembic 1.8.12"));
    REQUIRE_THAT(archiveMd, Contains(";_ai_Application=vdbhair "));
    // Time sampling 0: at most 1 sample, 1 s per cycle, one stored time 0.
    const auto ts = r.childData(root, 4, "time samplings");
    REQUIRE(ts.size == 24);
    std::uint32_t maxSamples, numTimes;
    double tpc, t0;
    std::memcpy(&maxSamples, ts.bytes, 4);
    std::memcpy(&tpc, ts.bytes + 4, 8);
    std::memcpy(&numTimes, ts.bytes + 12, 4);
    std::memcpy(&t0, ts.bytes + 16, 8);
    REQUIRE((maxSamples == 1 && tpc == 1.0 && numTimes == 1 && t0 == 0.0));
    const auto indexed = r.childData(root, 5, "indexed");
    const std::string index(indexed.bytes, indexed.size);
    REQUIRE_THAT(index, Contains("schema=AbcGeom_Curve_v2;schemaBaseType=AbcGeom_GeomBase_v1;schemaObjTitle=AbcGeom_Curve_v2:.geom"));
    REQUIRE_THAT(index, Contains("arrayExtent=1;geoScope=vtx;isGeomParam=true;podExtent=1;podName=float32_t"));
    // The top object: no properties, one child "hair"; its headers end with 32 bytes of hashes.
    const auto top = r.group(r.childGroup(root, 2, "top"), "top");
    REQUIRE(top.children.size() == 3);
    REQUIRE(top.children[0] == ogawa::kEmptyGroup);
    const auto headers = r.childData(top, 2, "headers");
    REQUIRE(headers.size == 4 + 4 + 1 + 32);
    REQUIRE(std::string(headers.bytes + 4, 4) == "hair");
    // /hair/.geom: property groups in the reference library's order, then the headers.
    const auto hair = r.group(r.childGroup(top, 1, "hair"), "hair");
    const auto props = r.group(r.childGroup(hair, 0, "props"), "props");
    const auto geom = r.group(r.childGroup(props, 0, ".geom"), ".geom");
    // .selfBnds P nVertices curveBasisAndType width .arbGeomParams (Cd, groom_width), headers
    REQUIRE(geom.children.size() == 6 + 1);
    const auto h = r.childData(geom, 6, "geom headers");
    const std::string text(h.bytes, h.size);
    std::size_t at = 0;
    for (const char* name : {".selfBnds", "P", "nVertices", "curveBasisAndType", "width", ".arbGeomParams"}) {
        const std::size_t found = text.find(name, at);
        CAPTURE(name);
        REQUIRE(found != std::string::npos);
        at = found;
    }
    // P: sample 0 is the digest (MurmurHash3 of the bytes) and the points, dimensions empty.
    const auto pGroup = r.group(r.childGroup(geom, 1, "P"), "P");
    REQUIRE(pGroup.children.size() == 2);
    REQUIRE(pGroup.children[1] == ogawa::kEmptyData);
    const auto p0 = r.childData(pGroup, 0, "P sample");
    REQUIRE(p0.size == 16 + 12 * s.numVertices());
    REQUIRE(std::memcmp(p0.bytes + 16, s.positions.data(), 12 * s.numVertices()) == 0);
    std::uint64_t digest[2];
    ogawa::murmur3x64_128(s.positions.data(), 12 * s.numVertices(), digest);
    REQUIRE(std::memcmp(p0.bytes, digest, 16) == 0);
    // curveBasisAndType: kLinear, kNonPeriodic, kNoBasis.
    const auto bt = r.childData(r.group(r.childGroup(geom, 3, "bt"), "bt"), 0, "bt sample");
    REQUIRE(bt.size == 20);
    REQUIRE(std::string(bt.bytes + 16, 4) == std::string("\x01\x00\x00\x00", 4));
    // .selfBnds: the box of the points as 6 doubles.
    const auto bb = r.childData(r.group(r.childGroup(geom, 0, "bounds"), "bounds"), 0, "bounds sample");
    double box[6];
    std::memcpy(box, bb.bytes + 16, 48);
    const BBox expect = computeBBox(s);
    REQUIRE((box[0] == expect.min.x() && box[4] == expect.max.y() && box[5] == expect.max.z()));
}

TEST_CASE("readAbc: cubic Bezier, B-spline and Catmull-Rom curves become polylines on the curve", "[io][abc]")
{
    // One 7-point Bezier (two spans) on a straight line x = 0..6 and one on a parabola.
    TestCurves bez{"bezier", {}, {7}, {0, 0, 1, 1}, {}, "vtx", 1};
    for (int i = 0; i < 7; ++i) bez.points.emplace_back(float(i), 0.f, 0.f);
    TestCurves bsp = bez;
    bsp.name = "bspline";
    bsp.basisAndType = {0, 0, 2, 2};
    TestCurves cat = bez;
    cat.name = "catmull";
    cat.basisAndType = {0, 0, 3, 3};
    TestCurves lin{"linear", {Vec3f(0.f, 5.f, 0.f), Vec3f(1.f, 5.f, 0.f)}, {2}, {1, 0, 0, 0}, {}, "vtx", 1};
    const std::string path = test::writeBytes("cubic.abc", buildArchive({bez, bsp, cat, lin}, false));
    ReadOptions opts;
    opts.curveSamples = 9;
    ReadReport report;
    const StrandSet s = readAbc(path, opts, &report);
    REQUIRE(s.numStrands() == 4);  // hierarchy order: bezier, bspline, catmull, linear
    // Bezier: from the first to the last control point; B-spline of collinear evenly spaced
    // points: from (P0 + 4 P1 + P2) / 6 = 1 to 5; Catmull-Rom through P1 .. P5.
    const float ends[3][2] = {{0.f, 6.f}, {1.f, 5.f}, {1.f, 5.f}};
    for (std::size_t c = 0; c < 3; ++c) {
        CAPTURE(c);
        REQUIRE(s.size(c) == 9);
        REQUIRE(s.root(c).x() == Approx(ends[c][0]).margin(1e-5));
        REQUIRE(s.tip(c).x() == Approx(ends[c][1]).margin(1e-5));
        for (std::size_t v = s.begin(c); v < s.end(c); ++v) {
            REQUIRE(s.positions[v].y() == Approx(0.f).margin(1e-6));
            if (v > s.begin(c)) REQUIRE(s.positions[v].x() > s.positions[v - 1].x());
        }
    }
    REQUIRE(s.size(3) == 2);
    REQUIRE(s.positions[s.begin(3)] == Vec3f(0.f, 5.f, 0.f));
    REQUIRE(report.warnings.empty());
}

TEST_CASE("readAbc: several objects under an Xform, widths by scope, animation's first sample", "[io][abc]")
{
    TestCurves a{"a", {Vec3f(0.f), Vec3f(1.f, 0.f, 0.f), Vec3f(2.f, 0.f, 0.f)}, {3}, {1, 0, 0, 0}, {0.5f}, "con", 1};
    TestCurves b{"b", {Vec3f(0.f, 1.f, 0.f), Vec3f(1.f, 1.f, 0.f), Vec3f(0.f, 2.f, 0.f), Vec3f(1.f, 2.f, 0.f)},
                 {2, 2}, {1, 0, 0, 0}, {0.1f, 0.2f}, "uni", 3};
    const std::string path = test::writeBytes("objects.abc", buildArchive({a, b}, true));
    ReadReport report;
    const StrandSet s = readAbc(path, {}, &report);
    REQUIRE(s.numStrands() == 3);
    REQUIRE(s.positions[3] == Vec3f(0.f, 1.f, 0.f));  // b's first frame, not a later one
    REQUIRE(s.thickness.size() == 7);
    REQUIRE(s.thickness[0] == 0.5f);  // a's constant width, filled in
    REQUIRE(s.thickness[3] == 0.1f);  // uniform: per curve
    REQUIRE(s.thickness[6] == 0.2f);
    REQUIRE(report.warnings.size() == 1);
    REQUIRE_THAT(report.warnings[0], Contains("/groom/b/P has 3 samples; the first is read"));
}

TEST_CASE("readAbc: indexed widths are expanded; an index past the values is an error", "[io][abc]")
{
    TestCurves a{"a", {Vec3f(0.f), Vec3f(1.f, 0.f, 0.f), Vec3f(2.f, 0.f, 0.f), Vec3f(0.f, 1.f, 0.f), Vec3f(1.f, 1.f, 0.f)},
                 {3, 2}, {1, 0, 0, 0}, {0.5f, 0.25f}, "vtx", 1, {0, 1, 1, 0, 1}};
    const StrandSet s = readAbc(test::writeBytes("indexed.abc", buildArchive({a}, false)));
    REQUIRE(s.thickness == std::vector<float>{0.5f, 0.25f, 0.25f, 0.5f, 0.25f});
    a.widthIndices[3] = 2;
    REQUIRE_THROWS_WITH(readAbc(test::writeBytes("indexed_bad.abc", buildArchive({a}, false))),
                        Contains("/a/width.indices[3] = 2 but .vals has 2 values"));
}

TEST_CASE("readAbc: a parent Xform's operations are applied as Alembic composes them", "[io][abc]")
{
    // Operations translate (10, 0, 0), rotate Z 90 degrees, scale 2 (AbcGeom's XformSample order:
    // each premultiplies, so a point is scaled, then rotated, then translated).
    TestCurves a{"a", {Vec3f(0.f), Vec3f(1.f, 0.f, 0.f), Vec3f(0.f, 0.f, 1.f)}, {3}, {1, 0, 0, 0}, {}, "vtx", 1};
    const std::string path = test::writeBytes("xform.abc", buildArchive({a}, true, {0x10, 0x60, 0x00},
                                                                          {10, 0, 0, 90, 2, 2, 2}));
    ReadReport report;
    const StrandSet s = readAbc(path, {}, &report);
    REQUIRE(report.warnings.empty());
    REQUIRE(s.positions[0].x() == Approx(10.f).margin(1e-5));
    REQUIRE(s.positions[1].x() == Approx(10.f).margin(1e-5));
    REQUIRE(s.positions[1].y() == Approx(2.f).margin(1e-5));
    REQUIRE(s.positions[2].z() == Approx(2.f).margin(1e-5));
    REQUIRE(s.positions[2].y() == Approx(0.f).margin(1e-5));
    // Too few values for the operations is an error of its own.
    const std::string bad = test::writeBytes("xform_bad.abc", buildArchive({a}, true, {0x10, 0x30}, {1, 2, 3, 4}));
    REQUIRE_THROWS_WITH(readAbc(bad), Contains("the operations need more than the 4 values of .vals"));
}

TEST_CASE("readAbc: bad input is a FormatError naming the file, the byte and the rule", "[io][abc]")
{
    const std::string path = test::tempPath("bad_source.abc");
    writeAbc(path, test::sampleStrands(true));
    const std::string good = test::readBytes(path);
    ogawa::Reader r(good.data(), good.size(), "good");
    const auto root = r.group(r.rootPos(), "root");
    const std::uint64_t topPos = root.children[2];
    const auto top = r.group(topPos, "top");
    const auto geom = r.group(r.childGroup(r.group(r.childGroup(r.group(top.children[1], "hair"), 0, "p"), "p"), 0, "g"), "g");
    const auto nv = r.childData(r.group(geom.children[2], "nv"), 0, "nv");

    auto fails = [](const std::string& name, const std::string& bytes, const std::string& what) {
        const std::string p = test::writeBytes(name, bytes);
        CAPTURE(name);
        REQUIRE_THROWS_MATCHES(readAbc(p), FormatError, Catch::Matchers::Predicate<FormatError>([&](const FormatError& e) {
            const std::string m = e.what();
            return m.find("readAbc(" + p + "): at byte ") == 0 && m.find(what) != std::string::npos &&
                   m.find('\n') == std::string::npos;
        }, "names the file, the byte and " + what));
    };
    fails("truncated.abc", good.substr(0, good.size() / 2), "lies outside");
    fails("notogawa.abc", "\x89HDF\r\n\x1a\n" + good.substr(8), "no \"Ogawa\" magic");
    std::string unfinished = good;
    unfinished[5] = 0;
    fails("unfinished.abc", unfinished, "the writer did not finish the file");
    std::string count = good;
    setWord(count, r.rootPos(), 1ull << 40);
    fails("count.abc", count, "group declares 1099511627776 children but only");
    std::string outside = good;
    setWord(outside, r.rootPos() + 8 + 8 * 2, good.size() + 100);
    fails("outside.abc", outside, "lies outside the");
    std::string cycle = good;
    setWord(cycle, topPos + 8 + 8 * 1, topPos);  // /hair's group is the top object's own
    fails("cycle.abc", cycle, "group reached a second time");
    std::string dataSize = good;
    setWord(dataSize, nv.pos, 1ull << 50);
    fails("datasize.abc", dataSize, "data block declares 1125899906842624 bytes but only");
    std::string counts = good;
    const std::int32_t huge = 1 << 30;
    std::memcpy(&counts[nv.pos + 8 + 16], &huge, 4);
    fails("counts.abc", counts, "nVertices[0] = 1073741824 but only 52 of the 52 points remain");
    std::string nan = good;
    const float inf = std::numeric_limits<float>::infinity();
    const auto p0 = r.childData(r.group(geom.children[1], "P"), 0, "P");
    std::memcpy(&nan[p0.pos + 8 + 16 + 4], &inf, 4);
    fails("nan.abc", nan, "non-finite coordinate");
    // An archive without Curves is an error of its own.
    TestCurves none{"x", {Vec3f(0.f), Vec3f(1.f)}, {2}, {1, 0, 0, 0}, {}, "vtx", 1};
    std::string noCurves = buildArchive({none}, false);
    const std::string from = "schema=AbcGeom_Curve_v2;schemaObjTitle";
    noCurves.replace(noCurves.rfind(from) + 7, 16, "AbcGeom_Points_2");  // same length: the object is no Curves
    REQUIRE_THROWS_WITH(readAbc(test::writeBytes("nocurves.abc", noCurves)), Contains("no Curves object"));
}

TEST_CASE("readAbc: NURBS and Hermite curves are refused by name", "[io][abc]")
{
    TestCurves herm{"h", {Vec3f(0.f), Vec3f(1.f), Vec3f(2.f), Vec3f(3.f)}, {4}, {0, 0, 4, 4}, {}, "vtx", 1};
    REQUIRE_THROWS_AS(readAbc(test::writeBytes("hermite.abc", buildArchive({herm}, false))), UnsupportedError);
    TestCurves bad = herm;
    bad.basisAndType = {7, 0, 0, 0};
    REQUIRE_THROWS_WITH(readAbc(test::writeBytes("badtype.abc", buildArchive({bad}, false))), Contains("type 0-2"));
}

TEST_CASE("writeAbc: several objects; reading leaves simulation guides out when there is hair", "[io][abc]")
{
    StrandSet hair = test::sampleStrands(true), guides;
    guides.addStrand({Vec3f(0, 0, 0), Vec3f(0, 1, 0)});
    guides.addStrand({Vec3f(1, 0, 0), Vec3f(1, 1, 0)});
    AbcCurves g, h;
    g.name = "guides";
    g.strands = &guides;
    g.guides = true;
    g.groupId = {7, 8};
    h.strands = &hair;
    h.closestGuides.assign(3 * hair.numStrands(), 1);
    h.guideWeights.assign(3 * hair.numStrands(), 1.0f / 3.0f);
    const std::string path = test::tempPath("groom.abc");
    writeAbc(path, {g, h});
    ReadReport report;
    const StrandSet r = readAbc(path, {}, &report);
    REQUIRE(r.positions == hair.positions);
    REQUIRE(r.thickness == hair.thickness);
    REQUIRE(r.color == hair.color);
    REQUIRE(report.warnings.size() == 1);
    CHECK_THAT(report.warnings[0], Contains("2 guide curves (groom_guide = 1) left out"));
    // Hair first and guides after: the same.
    writeAbc(path, {h, g});
    REQUIRE(readAbc(path).positions == hair.positions);
    // Guides only: read whole, silently.
    writeAbc(path, {g});
    ReadReport only;
    REQUIRE(readAbc(path, {}, &only).positions == guides.positions);
    CHECK(only.warnings.empty());
    // Two hair objects: concatenated in order.
    AbcCurves h2 = h;
    h2.name = "more";
    writeAbc(path, {h, h2});
    REQUIRE(readAbc(path).numStrands() == 2 * hair.numStrands());
    // Refused: a repeated or empty name, a '/', sizes that do not fit the strands.
    REQUIRE_THROWS_WITH(writeAbc(path, {h, h}), Contains("two objects of one name"));
    AbcCurves bad = h;
    bad.name = "a/b";
    REQUIRE_THROWS_WITH(writeAbc(path, {bad}), Contains("has no '/'"));
    bad = h;
    bad.groupId = {1};
    REQUIRE_THROWS_WITH(writeAbc(path, {bad}), Contains("1 group ids for " + std::to_string(hair.numStrands()) + " strands"));
    bad = h;
    bad.guideWeights.pop_back();
    REQUIRE_THROWS_WITH(writeAbc(path, {bad}), Contains("three of each per strand"));
    REQUIRE_THROWS_AS(writeAbc(path, std::vector<AbcCurves>{}), ValueError);
}
