// Seed corpora for the fuzz harnesses (FuzzReader.cc), made at build time from small synthetic
// hairstyles so that nothing from the shared data (partly non-commercial) is ever committed.
//
// Usage: vdbhair_fuzz_seeds OUTDIR   (writes OUTDIR/<reader>/<seed files>)
#include <vdbhair/helicoid/Scene.h>
#include <vdbhair/io/DataFile.h>
#include <vdbhair/io/HairFile.h>
#include <vdbhair/io/ObjFile.h>
#include <vdbhair/io/PlyFile.h>
#include <vdbhair/io/UsdFile.h>
#include <vdbhair/io/AbcFile.h>
#include <vdbhair/io/VdbFile.h>
#include <vdbhair/io/VdbStrands.h>
#include <vdbhair/io/VdbPrescan.h>

#include <openvdb/io/File.h>
#include <openvdb/tools/LevelSetSphere.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>

namespace fs = std::filesystem;
using namespace vdbhair;

namespace {

/// Three short strands (2, 3 and 5 vertices) with colours and thickness: every optional array.
StrandSet tinyStyle()
{
    StrandSet s;
    for (int i = 0; i < 3; ++i) {
        std::vector<Vec3f> p;
        const int n = i == 0 ? 2 : i == 1 ? 3 : 5;
        for (int v = 0; v < n; ++v) p.emplace_back(float(i), 0.1f * float(v), 0.05f * std::sin(float(v)));
        s.addStrand(p);
    }
    for (std::size_t v = 0; v < s.numVertices(); ++v) {
        s.color.emplace_back(0.2f, 0.3f, 0.4f);
        s.thickness.push_back(0.01f);
    }
    return s;
}

template<typename T>
void put(std::string& b, T v) { b.append(reinterpret_cast<const char*>(&v), sizeof v); }

void writeRaw(const fs::path& p, const std::string& bytes) { std::ofstream(p, std::ios::binary).write(bytes.data(), std::streamsize(bytes.size())); }

/// .hair and .data as the writers make them: every optional array (.hair), and none.
void hairAndDataSeeds(const fs::path& out, const StrandSet& s, const StrandSet& plain)
{
    writeHair((out / "hair/all_arrays.hair").string(), s);
    writeHair((out / "hair/plain.hair").string(), plain);
    writeData((out / "data/tiny.data").string(), plain);
}

/// .obj: edges and polylines as the writer makes them, and issue 50's free-form curves.
void objSeeds(const fs::path& out, const StrandSet& s, const StrandSet& plain)
{
    writeObj((out / "obj/edges.obj").string(), s, ObjLineStyle::Edges);
    writeObj((out / "obj/polylines.obj").string(), plain, ObjLineStyle::Polylines);
    writeRaw(out / "obj/curves.obj",
             "v 0 0 0\nv 1 2 0\nv 3 2 0\nv 4 0 0\nv 5 -2 0 0.5\nv 7 -1 0\nv 8 0 0\n"
             "cstype bezier\ndeg 3\ncurv 0 2 1 2 3 4 5 6 7\nparm u 0 1 2\nend\n"
             "cstype rat bspline\ndeg 2\ncurv 0.0 1.0 -4 -3 \\\n -2 -1\nparm u 0 0 0 0.5 1 1 1\nend\n"
             "cstype cardinal\ndeg 3\ncurv 0 1 1 2 3 4 5\nend\n"
             "surf 0 1 0 1 1 2 3 4\nend\nl 1 2\n");
}

/// .ply: binary and ASCII as the writer makes them, and issue 50's line sets and points in runs
/// (the harness reads a .ply without topology with 4 points a strand).
void plySeeds(const fs::path& out, const StrandSet& s, const StrandSet& plain)
{
    writePly((out / "ply/binary.ply").string(), s, PlyEncoding::Binary);
    writePly((out / "ply/ascii.ply").string(), plain, PlyEncoding::Ascii);
    std::string runs = "ply\nformat binary_little_endian 1.0\nelement vertex 8\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
    for (int i = 0; i < 24; ++i) put(runs, float(i % 7) * 0.5f);
    writeRaw(out / "ply/runs_binary.ply", runs);
    writeRaw(out / "ply/runs_ascii.ply", "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nend_header\n"
                                         "0 0 0\n0 1 0\n0 2 0\n0 3 1\n");
    writeRaw(out / "ply/lineset_ascii.ply", "ply\nformat ascii 1.0\nelement vertex 5\nproperty float x\nproperty float y\nproperty float z\n"
                                            "element edge 3\nproperty int vertex1\nproperty int vertex2\nproperty uchar red\nend_header\n"
                                            "0 0 0\n0 1 0\n0 2 0\n5 5 5\n5 6 5\n1 0 9\n1 2 9\n4 3 9\n");
    std::string lines = "ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty double x\nproperty double y\nproperty double z\n"
                        "element edge 2\nproperty int vertex1\nproperty int vertex2\nend_header\n";
    for (int i = 0; i < 12; ++i) put(lines, double(i));
    for (std::int32_t v : {0, 1, 2, 3}) put(lines, v);
    writeRaw(out / "ply/lineset_binary.ply", lines);
}

/// .usda: the writer's, and cubic curves of each basis and wrap under nested transforms, and time samples.
void usdaSeeds(const fs::path& out, const StrandSet& s)
{
    writeUsda((out / "usda/tiny.usda").string(), s);
    writeRaw(out / "usda/cubic_xform.usda",
             "#usda 1.0\ndef Xform \"r\"\n{\n    double3 xformOp:translate = (1, 0, 0)\n    float3 xformOp:rotateXYZ = (30, 0, 90)\n"
             "    uniform token[] xformOpOrder = [\"xformOp:translate\", \"!invert!xformOp:rotateXYZ\"]\n"
             "    def BasisCurves \"b\"\n    {\n        quatf xformOp:orient = (0.8660254, 0.5, 0, 0)\n"
             "        uniform token[] xformOpOrder = [\"!resetXformStack!\", \"xformOp:orient\"]\n"
             "        uniform token type = \"cubic\"\n        uniform token basis = \"bspline\"\n        uniform token wrap = \"pinned\"\n"
             "        int[] curveVertexCounts = [4, 5]\n"
             "        point3f[] points = [(0,0,0), (1,0,0), (1,1,0), (2,1,0), (0,0,1), (0,1,1), (1,1,1), (1,2,1), (2,2,2)]\n"
             "        float[] widths = [1, 2, 3, 4, 5, 6, 7, 8, 9] (interpolation = \"vertex\")\n    }\n"
             "    def BasisCurves \"z\"\n    {\n        uniform token type = \"cubic\"\n        uniform token basis = \"bezier\"\n"
             "        int[] curveVertexCounts = [4]\n        point3f[] points.timeSamples = { 1: [(0,0,0), (1,0,0), (1,1,0), (2,1,0)], 0: [(0,0,0), (1,0,0), (1,1,0), (2,1,0)] }\n"
             "        float[] widths = [1, 2] (interpolation = \"varying\")\n    }\n}\n");
}

/// .abc: the writer's, and Unreal's groom as interpolate writes it: guides and hair, groups, closest
/// guides and weights.
void abcSeeds(const fs::path& out, const StrandSet& s, const StrandSet& plain)
{
    writeAbc((out / "abc/tiny.abc").string(), s);
    writeAbc((out / "abc/plain.abc").string(), plain);
    AbcCurves guides, hair;
    guides.name = "guides";
    guides.strands = &plain;
    guides.guides = true;
    guides.groupId.assign(plain.numStrands(), 3);
    hair.strands = &s;
    hair.groupId.assign(s.numStrands(), 3);
    hair.closestGuides.assign(3 * s.numStrands(), 0);
    hair.guideWeights.assign(3 * s.numStrands(), 0.5f);
    writeAbc((out / "abc/groom.abc").string(), {guides, hair});
}

/// .vdb points grids: float positions, and fixed16 ones with colour.
void vdbStrandSeeds(const fs::path& out, const StrandSet& s, const StrandSet& plain)
{
    writeVdbStrands((out / "vdb/float.vdb").string(), plain);
    VdbPointsOptions fixed;
    fixed.codec = PositionCodec::Fixed16;
    writeVdbStrands((out / "vdb/fixed16_colour.vdb").string(), s, fixed);
}

/// .vdb grids: fields, a level set and a file of several grids (issue 51), each under 64 KiB; after
/// vdbStrandSeeds() (several.vdb holds vdb/float.vdb's grids too).
void vdbGridSeeds(const fs::path& out)
{
    auto tangent = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.f));
    auto density = openvdb::FloatGrid::create(0.f);
    for (int i = 0; i < 40; ++i) {
        const openvdb::Coord c(i, (i * 7) % 13, (i * 3) % 17);
        tangent->tree().setValue(c, openvdb::Vec3s(0.f, 1.f, 0.1f * float(i % 5)));
        density->tree().setValue(c, 0.025f * float(i));
    }
    tangent->setName("tangent");
    tangent->setVectorType(openvdb::VEC_CONTRAVARIANT_RELATIVE);
    density->setName("density");
    density->setGridClass(openvdb::GRID_FOG_VOLUME);
    auto sphere = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(3.f, openvdb::Vec3f(8.f), 1.f, 2.f);
    sphere->setName("surface");
    auto wide = openvdb::Vec3DGrid::create();
    wide->tree().setValue(openvdb::Coord(4096, 0, 0), openvdb::Vec3d(1.0, 2.0, 3.0));
    auto flags = openvdb::BoolGrid::create();
    flags->denseFill(openvdb::CoordBBox(openvdb::Coord(0), openvdb::Coord(9)), true);
    writeVdbGrids((out / "vdb/field.vdb").string(), {tangent, density}, "seeds");
    writeVdbGrids((out / "vdb/level_set.vdb").string(), {sphere}, "seeds");
    openvdb::GridCPtrVec many{density, sphere, wide, flags};
    for (const auto& g : readVdbGrids((out / "vdb/float.vdb").string(), "seeds")) many.push_back(g);
    writeVdbGrids((out / "vdb/several.vdb").string(), many, "seeds");
    // The overflow of Debian's OpenVDB 10.0.1 (fixed in 11.0, PR #1701): a leaf chunk of -1000
    // bytes is read uncompressed into its smaller buffer. Also tests/io/data/fuzz_vdb_negative_chunk.vdb.
    std::vector<VdbPrescanField> fields;
    prescanVdbFile((out / "vdb/field.vdb").string(), "seeds", nullptr, &fields);
    for (auto it = fields.rbegin(); it != fields.rend(); ++it) {  // the last: a leaf's buffer
        const VdbPrescanField& f = *it;
        if ((f.kind != "chunk64blosc" && f.kind != "chunk64zip") || f.destination == 0) continue;
        std::ifstream in(out / "vdb/field.vdb", std::ios::binary);
        std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        const std::int64_t negative = -1000;
        bytes.replace(f.offset, 8, reinterpret_cast<const char*>(&negative), 8);
        writeRaw(out / "vdb/negative_chunk.vdb", bytes);
        break;
    }
    auto zip = sphere->deepCopy();
    openvdb::io::File file((out / "vdb/level_set_zip.vdb").string());
    file.setCompression(openvdb::io::COMPRESS_ZIP | openvdb::io::COMPRESS_ACTIVE_MASK);
    file.write({zip});
    file.close();
}

/// CT2Hair .bin: int32 strands; per strand int32 count and 7 floats per vertex.
void binSeeds(const fs::path& out, const StrandSet& plain)
{
    std::string bin;
    put(bin, std::int32_t(plain.numStrands()));
    for (std::size_t i = 0; i < plain.numStrands(); ++i) {
        put(bin, std::int32_t(plain.size(i)));
        for (std::size_t v = plain.begin(i); v < plain.end(i); ++v) {
            for (int c = 0; c < 3; ++c) put(bin, plain.positions[v][c]);
            for (int c = 0; c < 4; ++c) put(bin, 0.5f);
        }
    }
    writeRaw(out / "bin/tiny.bin", bin);
}

/// TressFX: binary 4.x (160-byte header; positions as xyzw) and 3.0 (296 bytes), and ASCII 2.0.
void tfxSeeds(const fs::path& out)
{
    for (const float version : {4.f, 3.f}) {
        const std::uint32_t nS = 2, nV = 3, header = version == 4.f ? 160 : 296, stride = version == 4.f ? 4 : 3;
        std::string t;
        put(t, version);
        put(t, nS);
        put(t, nV);
        if (version == 4.f) put(t, header);
        t.resize(version == 4.f ? 160 : 144, '\0');
        if (version == 3.f) {
            put(t, header);
            t.resize(296, '\0');
        }
        for (std::uint32_t i = 0; i < nS * nV; ++i)
            for (std::uint32_t c = 0; c < stride; ++c) put(t, c == 3 ? 1.f : float(i) * 0.1f + float(c));
        writeRaw(out / (version == 4.f ? "tfx/binary4.tfx" : "tfx/binary3.tfx"), t);
    }
    writeRaw(out / "tfx/ascii.tfx", "version 2.0\nscale 1.0\nnumStrands 2\nstrand 0 numVerts 2 texcoord 0.5 0.5\n0 0 0\n1 1 1\n"
                                    "strand 1 numVerts 3 texcoord 0 1\n0 0 1\n0 1 1\n0 2 1.5\n");
}

/// HairNet convdata: a float32 .npy of shape (4 * points, rows, columns).
void convdataSeeds(const fs::path& out)
{
    std::string h = "{'descr': '<f4', 'fortran_order': False, 'shape': (8, 1, 2), }";
    while ((10 + h.size() + 1) % 64) h += ' ';
    h += '\n';
    std::string b = "\x93NUMPY";
    b += char(1);
    b += char(0);
    put(b, std::uint16_t(h.size()));
    b += h;
    for (int i = 0; i < 16; ++i) put(b, float(i % 5) * 0.25f);
    writeRaw(out / "convdata/tiny.convdata", b);
}

/// Meshes: a tetrahedron as PLY (ascii and binary faces) and OBJ.
void meshSeeds(const fs::path& out)
{
    writeRaw(out / "mesh/tet_ascii.ply", "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
                                         "element face 4\nproperty list uchar int vertex_indices\nend_header\n"
                                         "0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n");
    std::string b = "ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
                    "element face 2\nproperty list uchar int vertex_indices\nend_header\n";
    for (float f : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f}) put(b, f);
    for (int face = 0; face < 2; ++face) {
        put(b, std::uint8_t(4));
        for (std::int32_t i : {0, 1, 2, 3}) put(b, i);
    }
    writeRaw(out / "mesh/quads_binary.ply", b);
    writeRaw(out / "mesh/tet.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1/1 2/2 4/3\nf 1//1 4//1 3//1\nf -3 -2 -1\n");
}

/// Scenes: every record the reader knows.
void sceneSeeds(const fs::path& out)
{
    writeRaw(out / "scene/full.json", R"({"vdbhair": "scene/1", "seed": 7, "step": 0.05, "integrator": "rk4",
 "head": {"sphere": [0, 0, 0, 0.5]},
 "guides": [
  {"root": [0,0,0], "frame": {"tangent": [1,0,0], "normal": [0,1,0]},
   "pieces": [{"k": [1.0, -0.1, 0.3, 1.0], "length": 0.5, "roll": 0.0}],
   "waviness": {"amplitude": 0.02, "frequency": 40.0},
   "wisp": {"count": 3, "radius": 0.05, "fanning": 0.1, "normal": [0, 1, 0], "strays": 0.1}},
  {"root": [1,0,0], "frame": {"tangent": [0,0,1], "normal": [0,1,0]}, "step": 0.1,
   "pieces": [{"k": [0.5, 0, 0, 0], "length": 0.3}, {"k": [0, 0, 2.0, 0.3], "length": 0.2, "roll": 1.0}],
   "fit": {"frechet": 0.01, "nested": [[1, 2], {"a": null, "b": true}]}}]}
)");
    writeRaw(out / "scene/minimal.json", R"({"vdbhair": "scene/1", "guides": []})");
}

} // namespace

int main(int argc, char** argv)
{
    if (argc != 2) {
        std::cerr << "usage: vdbhair_fuzz_seeds OUTDIR\n";
        return 2;
    }
    const fs::path out = argv[1];
    for (const char* r : {"hair", "data", "bin", "obj", "ply", "tfx", "convdata", "usda", "abc", "vdb", "mesh", "scene"}) fs::create_directories(out / r);
    initializeOpenVdb();
    const StrandSet s = tinyStyle();
    StrandSet plain = s;
    plain.color.clear();
    plain.thickness.clear();

    hairAndDataSeeds(out, s, plain);
    objSeeds(out, s, plain);
    plySeeds(out, s, plain);
    usdaSeeds(out, s);
    abcSeeds(out, s, plain);
    vdbStrandSeeds(out, s, plain);
    vdbGridSeeds(out);
    binSeeds(out, plain);
    tfxSeeds(out);
    convdataSeeds(out);
    meshSeeds(out);
    sceneSeeds(out);
    return 0;
}
