#include "../TestUtil.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/io/MeshFile.h>
#include <vdbhair/render/StrandRenderer.h>

using namespace vdbhair;
using Catch::Matchers::Contains;

namespace {

/// A closed latitude-longitude sphere of radius r about c as OBJ text (quads and triangle fans at the poles).
std::string sphereObj(const Vec3f& c, float r, int rings = 16, int sectors = 24)
{
    std::string s;
    auto vtx = [&](float x, float y, float z) {
        s += "v " + std::to_string(c.x() + r * x) + " " + std::to_string(c.y() + r * y) + " " + std::to_string(c.z() + r * z) + "\n";
    };
    vtx(0, 1, 0);  // north pole: vertex 1
    for (int i = 1; i < rings; ++i) {
        const float th = float(M_PI) * float(i) / float(rings);
        for (int j = 0; j < sectors; ++j) {
            const float ph = 2.f * float(M_PI) * float(j) / float(sectors);
            vtx(std::sin(th) * std::cos(ph), std::cos(th), std::sin(th) * std::sin(ph));
        }
    }
    vtx(0, -1, 0);  // south pole
    const int south = 2 + (rings - 1) * sectors;
    auto at = [&](int i, int j) { return 2 + (i - 1) * sectors + (j % sectors); };
    for (int j = 0; j < sectors; ++j) s += "f 1 " + std::to_string(at(1, j + 1)) + " " + std::to_string(at(1, j)) + "\n";
    for (int i = 1; i + 1 < rings; ++i)
        for (int j = 0; j < sectors; ++j)
            s += "f " + std::to_string(at(i, j)) + "/1/1 " + std::to_string(at(i, j + 1)) + "//1 " + std::to_string(at(i + 1, j + 1)) +
                 " " + std::to_string(at(i + 1, j)) + "\n";
    for (int j = 0; j < sectors; ++j) s += "f " + std::to_string(south) + " " + std::to_string(at(rings - 1, j)) + " " + std::to_string(at(rings - 1, j + 1)) + "\n";
    return s;
}

} // namespace

TEST_CASE("readObjMesh: vertices, polygons split into fans, index forms and negative indices", "[io][mesh]")
{
    const std::string path = test::writeBytes("quad.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//1 4//1\nf -4 -3 -1\n");
    const TriangleMesh m = readTriangleMesh(path);
    REQUIRE(m.vertices.size() == 4);
    REQUIRE(m.triangles.size() == 3);
    CHECK(m.triangles[0] == std::array<std::uint32_t, 3>{0, 1, 2});
    CHECK(m.triangles[1] == std::array<std::uint32_t, 3>{0, 2, 3});
    CHECK(m.triangles[2] == std::array<std::uint32_t, 3>{0, 1, 3});

    const TriangleMesh sphere = readTriangleMesh(test::writeBytes("sphere.obj", sphereObj(Vec3f(0.f), 1.f)));
    CHECK(sphere.triangles.size() == std::size_t(24 * 2 + 14 * 24 * 2));
    for (const Vec3f& v : sphere.vertices) CHECK(std::abs(v.length() - 1.f) < 1e-5f);
}

TEST_CASE("readPlyMesh: ascii faces of any size; the shared heads read with their counts", "[io][mesh][data]")
{
    const std::string ply = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
                            "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n";
    const TriangleMesh m = readTriangleMesh(test::writeBytes("quad.ply", ply));
    CHECK(m.vertices.size() == 4);
    CHECK(m.triangles.size() == 2);

    VDBHAIR_REQUIRE_SHARED_DATA();
    const std::string scalp = test::sharedData() + "/scalp";
    const TriangleMesh woman = readTriangleMesh(scalp + "/cem_yuksel/woman_head.ply");
    CHECK(woman.vertices.size() == 43662);
    CHECK(woman.triangles.size() == 78520);
    const TriangleMesh bangs = readTriangleMesh(scalp + "/ct2hair/Bangs_head.ply");  // with extra double s, t properties
    CHECK(bangs.vertices.size() == 3943);
    CHECK(bangs.triangles.size() == 7694);
    const TriangleMesh sintel = readTriangleMesh(scalp + "/sintel/sintel.obj");
    CHECK(sintel.vertices.size() == 3046);
    CHECK(sintel.triangles.size() == 5952);
}

TEST_CASE("readTriangleMesh: bad meshes are errors naming the file and the rule", "[io][mesh]")
{
    CHECK_THROWS_WITH(readTriangleMesh(test::writeBytes("bad_index.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n")),
                      Contains("bad_index.obj") && Contains("vertex index 9 is out of range"));
    CHECK_THROWS_WITH(readTriangleMesh(test::writeBytes("no_faces.obj", "v 0 0 0\n")), Contains("no faces"));
    CHECK_THROWS_WITH(readTriangleMesh(test::writeBytes("big.ply", "ply\nformat binary_little_endian 1.0\nelement vertex 1000000000\n"
                                                                   "property float x\nproperty float y\nproperty float z\nelement face 0\n"
                                                                   "property list uchar int vertex_indices\nend_header\n")),
                      Contains("declares 1000000000 items"));
    CHECK_THROWS_WITH(readTriangleMesh(test::writeBytes("bad_face.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
                                                                        "property float y\nproperty float z\nelement face 1\n"
                                                                        "property list uchar int vertex_indices\nend_header\n"
                                                                        "0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n")),
                      Contains("face 0 names vertex 3"));
    CHECK_THROWS_AS(readTriangleMesh(test::writeBytes("mesh.stl", "solid")), UnsupportedError);
}

TEST_CASE("renderStrands --head: the head hides hair behind it and not hair in front", "[render][mesh]")
{
    const TriangleMesh sphere = readTriangleMesh(test::writeBytes("head.obj", sphereObj(Vec3f(0.f), 1.f, 24, 32)));
    // Two horizontal strands across the sphere's middle, one behind it (z = -1.5), one in front (z = +1.5)
    // but lower, so the front view (from +z) shows them at different rows.
    StrandSet behind, front;
    behind.addStrand(std::vector<Vec3f>{Vec3f(-0.5f, 0.3f, -1.5f), Vec3f(0.5f, 0.3f, -1.5f)});
    front.addStrand(std::vector<Vec3f>{Vec3f(-0.5f, -0.3f, 1.5f), Vec3f(0.5f, -0.3f, 1.5f)});
    RenderParams rp;
    rp.view = View::Front;
    rp.width = rp.height = 128;
    rp.head = &sphere;
    rp.hairColor = Vec3f(0.f, 0.f, 0.f);
    BBox frame = meshBBox(sphere);
    rp.frame = frame;
    // The pixels along a strand's projected centre row, against the same render without it.
    auto changed = [&](const StrandSet& s, const RenderParams& p) {
        const Image with = renderStrands(s, p);
        StrandSet none;
        none.addStrand(std::vector<Vec3f>{Vec3f(9.f, 9.f, 9.f), Vec3f(9.f, 9.f, 9.01f)});  // off the framed image
        const Image without = renderStrands(none, p);
        const Vec3d q = projectToImage(Vec3d(0.0, s.positions[0].y(), s.positions[0].z()), p, frame);
        float most = 0.f;
        for (int dy = -1; dy <= 1; ++dy) {
            for (int dx = -8; dx <= 8; ++dx) {
                const int x = int(q.x()) + dx, y = int(q.y()) + dy;
                most = std::max(most, (with.at(x, y) - without.at(x, y)).length());
            }
        }
        return most;
    };
    CHECK(changed(front, rp) > 0.1f);    // drawn over the head
    CHECK(changed(behind, rp) == 0.f);   // hidden behind it: not one pixel differs
    rp.head = nullptr;
    CHECK(changed(behind, rp) > 0.1f);   // without the head it shows
}

TEST_CASE("readPlyMesh: list counts are whole numbers within what is left of the file (fuzz_mesh, issue 22)", "[io][mesh][fuzz]")
{
    // An ascii face whose count is 3.9e85: converting it to an integer was undefined behaviour.
    REQUIRE_THROWS_WITH(readTriangleMesh(test::regressionInput("fuzz_mesh_list_count.ply")),
                        Contains("line 15: list 'vertex_indices' declares 3.88889e+85 items but fewer remain in the file"));
    const std::string head = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                             "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n";
    REQUIRE(readTriangleMesh(test::writeBytes("tri.ply", head + "3 0 1 2\n")).triangles.size() == 1);
    REQUIRE_THROWS_WITH(readTriangleMesh(test::writeBytes("tri4.ply", head + "4 0 1 2\n")),
                        Contains("line 13: list 'vertex_indices' declares 4 items but fewer remain in the file"));
    REQUIRE_THROWS_WITH(readTriangleMesh(test::writeBytes("tri_frac.ply", head + "2.5 0 1 2\n")),
                        Contains("line 13: list 'vertex_indices' has count 2.5; a list count is a whole number, 0 or more"));
    REQUIRE_THROWS_WITH(readTriangleMesh(test::writeBytes("tri_nan.ply", head + "nan 0 1 2\n")),
                        Contains("list 'vertex_indices' has count nan"));
}
