#include "../TestUtil.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/render/SphereMesh.h>
#include <vdbhair/render/StrandRenderer.h>

#include <map>

using namespace vdbhair;

TEST_CASE("makeSphereMesh: a closed sphere of the given centre and radius, wound outwards", "[render]")
{
    const Vec3d c(1.0, -2.0, 3.0);
    const double r = 10.0;
    const TriangleMesh m = makeSphereMesh(c, r);
    REQUIRE(m.triangles.size() == 2 * 48 * 23);
    REQUIRE(m.vertices.size() == 2 + 48 * 23);
    for (const Vec3f& v : m.vertices) REQUIRE((Vec3d(v) - c).length() == Approx(r).margin(1e-5));
    // Signed volume (divergence theorem) and area: positive, i.e. wound outwards, and close to the
    // sphere's own (an inscribed polyhedron of 2,208 triangles: within 2 %).
    double volume = 0.0, area = 0.0;
    for (const auto& t : m.triangles) {
        for (std::uint32_t i : t) REQUIRE(i < m.vertices.size());
        const Vec3d a = Vec3d(m.vertices[t[0]]) - c, b = Vec3d(m.vertices[t[1]]) - c, d = Vec3d(m.vertices[t[2]]) - c;
        volume += a.dot(b.cross(d)) / 6.0;
        area += 0.5 * (b - a).cross(d - a).length();
    }
    CHECK(volume == Approx(4.0 / 3.0 * M_PI * r * r * r).epsilon(0.02));
    CHECK(area == Approx(4.0 * M_PI * r * r).epsilon(0.02));
    // Every edge is shared by exactly two triangles, in opposite directions: closed and oriented.
    std::map<std::pair<std::uint32_t, std::uint32_t>, int> edges;
    for (const auto& t : m.triangles) {
        for (int k = 0; k < 3; ++k) ++edges[{t[k], t[(k + 1) % 3]}];
    }
    for (const auto& [e, n] : edges) {
        CAPTURE(e.first, e.second);
        REQUIRE(n == 1);
        REQUIRE(edges.count({e.second, e.first}) == 1);
    }
    const BBox box = meshBBox(m);
    CHECK(box.min.x() == Approx(c.x() - r).margin(0.1));
    CHECK(box.max.y() == Approx(c.y() + r).margin(1e-5));
    REQUIRE_THROWS_AS(makeSphereMesh(c, 0.0), ValueError);
    REQUIRE_THROWS_AS(makeSphereMesh(c, 1.0, 1, 8), ValueError);
}

TEST_CASE("makeSphereMesh: drawn as a head, it hides the strands behind it", "[render]")
{
    // Seen from the front (along -z), a strand behind the sphere changes nothing in the image
    // when the sphere is drawn, and shows without it.
    StrandSet both, front;
    const std::vector<Vec3f> behind{Vec3f(-0.5f, 0.f, -3.f), Vec3f(0.5f, 0.f, -3.f)}, above{Vec3f(-3.f, 2.f, 0.f), Vec3f(3.f, 2.f, 0.f)};
    both.addStrand(behind);
    both.addStrand(above);
    front.addStrand(above);
    const TriangleMesh head = makeSphereMesh(Vec3d(0.0), 1.5);
    RenderParams rp;
    rp.view = View::Front;
    rp.width = rp.height = 120;
    rp.frame = computeBBox(both);
    rp.frame->expand(meshBBox(head).min);
    rp.frame->expand(meshBBox(head).max);
    rp.head = &head;
    REQUIRE(renderStrands(both, rp).rgb == renderStrands(front, rp).rgb);
    rp.head = nullptr;
    REQUIRE(renderStrands(both, rp).rgb != renderStrands(front, rp).rgb);
}
