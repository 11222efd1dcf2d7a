#include "../TestUtil.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/helicoid/GroomControls.h>
#include <vdbhair/helicoid/GuideInterpolation.h>
#include <vdbhair/io/FileUtil.h>
#include <vdbhair/io/IdList.h>
#include <vdbhair/io/VdbFile.h>
#include <vdbhair/scalp/RootValues.h>
#include <vdbhair/scalp/ScalpRegion.h>
#include <vdbhair/strands/Measures.h>

#include <openvdb/openvdb.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>

using namespace vdbhair;
using Catch::Matchers::Contains;

namespace {

/// A straight strand from @a root along @a dir, @a n vertices over @a length.
void addStraight(StrandSet& s, const Vec3f& root, const Vec3f& dir, float length, std::size_t n)
{
    std::vector<Vec3f> p(n);
    for (std::size_t k = 0; k < n; ++k) p[k] = root + dir * (length * float(k) / float(n - 1));
    s.addStrand(p);
}

std::vector<Vec3d> rootsOf(const StrandSet& s)
{
    std::vector<Vec3d> r;
    for (std::size_t i = 0; i < s.numStrands(); ++i) r.emplace_back(s.root(i).x(), s.root(i).y(), s.root(i).z());
    return r;
}

std::string tempPath(const std::string& name)
{
    return (std::filesystem::temp_directory_path() / ("vdbhair_groom_" + std::to_string(::getpid()) + "_" + name)).string();
}

} // namespace

TEST_CASE("curl winds a straight hair into the helix of Eq. 4 and keeps its root", "[groom]")
{
    // Oracle: about a straight line along z, Eq. 4's offset is a circle of radius a in the x-y plane
    // turning by b per unit of arc length; the ramp holds the root, one wavelength long.
    StrandSet s;
    addStraight(s, Vec3f(1.f, 2.f, 3.f), Vec3f(0.f, 0.f, 1.f), 10.f, 11);
    GroomParams g;
    g.curl.amplitude = 0.5;
    g.curl.frequency = 2.0 * M_PI;  // a turn a unit
    const GroomStats st = applyGroomControls(s, g);
    CHECK(st.curled == 1);
    REQUIRE(s.size(0) == std::size_t(10 * kCurlVerticesPerTurn) + 1);
    CHECK(st.addedVertices == s.size(0) - 11);
    CHECK((s.root(0) - Vec3f(1.f, 2.f, 3.f)).length() < 1e-6f);
    double prevAngle = 0.0;
    for (std::size_t k = 0; k < s.size(0); ++k) {
        const Vec3f p = s.data(0)[k];
        const double z = double(p.z()) - 3.0;
        CHECK(z == Approx(10.0 * double(k) / double(s.size(0) - 1)).margin(1e-4));  // the offset is across the axis only
        const double r = std::hypot(double(p.x()) - 1.0, double(p.y()) - 2.0);
        if (z >= 1.0) {
            CHECK(r == Approx(0.5).margin(1e-4));
            const double angle = std::atan2(double(p.y()) - 2.0, double(p.x()) - 1.0);
            if (k > 0 && z > 1.2) {
                double d = angle - prevAngle;
                while (d < -M_PI) d += 2.0 * M_PI;
                while (d > M_PI) d -= 2.0 * M_PI;
                CHECK(std::abs(d) == Approx(2.0 * M_PI * 10.0 / double(s.size(0) - 1)).margin(1e-3));
            }
            prevAngle = angle;
        } else {
            CHECK(r <= 0.5 + 1e-5);
            prevAngle = std::atan2(double(p.y()) - 2.0, double(p.x()) - 1.0);
        }
    }
}

TEST_CASE("clump centres are a Poisson-disk set that every root is within reach of", "[groom]")
{
    std::mt19937 rng(4);
    std::uniform_real_distribution<double> u(0.0, 10.0);
    std::vector<Vec3d> roots(3000);
    for (Vec3d& r : roots) r = Vec3d(u(rng), u(rng), 0.1 * u(rng));
    std::vector<std::uint32_t> groups(roots.size());
    for (std::size_t i = 0; i < roots.size(); ++i) groups[i] = roots[i].x() < 5.0 ? 0 : 1;  // a parting at x = 5
    const double radius = 0.7;
    const std::vector<std::uint32_t> c = clumpCentres(roots, radius, groups, 9);
    std::vector<std::uint32_t> centres;
    for (std::size_t i = 0; i < roots.size(); ++i) {
        if (c[i] == i) centres.push_back(std::uint32_t(i));
        REQUIRE(c[c[i]] == c[i]);                                // joins a centre
        CHECK(groups[c[i]] == groups[i]);                        // of its own group
        CHECK((roots[c[i]] - roots[i]).length() < radius);      // within reach
    }
    for (std::size_t a = 0; a < centres.size(); ++a)
        for (std::size_t b = a + 1; b < centres.size(); ++b)
            if (groups[centres[a]] == groups[centres[b]]) CHECK((roots[centres[a]] - roots[centres[b]]).length() >= radius);
    // Area 100 over disks of radius 0.7: a packing holds at most ~100 / (0.866 * 0.7^2) = 236 centres; far fewer than the roots.
    CHECK(centres.size() > 60);
    CHECK(centres.size() < 400);
    CHECK(clumpCentres(roots, radius, groups, 9, false) == c);  // any thread count
    REQUIRE_THROWS_WITH(clumpCentres(roots, 1e-9, {}, 0), Contains("over 2^20 clumps"));
}

TEST_CASE("a clump pulls each hair to its centre's hair along the length; groups and unlike shapes stay apart", "[groom]")
{
    // Two parallel straight hairs 0.2 apart: one is the centre; with tightness 1 the other's tip
    // meets the centre's tip and its middle goes half way (profile 1), its root stays.
    StrandSet s;
    addStraight(s, Vec3f(0.f, 0.f, 0.f), Vec3f(0.f, 0.f, 1.f), 4.f, 9);
    addStraight(s, Vec3f(0.2f, 0.f, 0.f), Vec3f(0.f, 0.f, 1.f), 4.f, 9);
    const StrandSet before = s;
    GroomParams g;
    g.clump.radius = 1.0;
    g.clump.tightness = 1.0;
    GroomStats st = applyGroomControls(s, g);
    CHECK(st.clumps == 1);
    CHECK(st.clumped == 1);
    const std::size_t member = (s.tip(0) - before.tip(0)).length() > 0.f ? 0 : 1, centre = 1 - member;
    CHECK((s.tip(member) - s.tip(centre)).length() < 1e-6f);
    CHECK((s.root(member) - before.root(member)).length() == 0.f);
    CHECK((s.data(member)[4] - (before.data(member)[4] + (before.data(centre)[4] - before.data(member)[4]) * 0.5f)).length() < 1e-6f);
    for (std::size_t k = 0; k < 9; ++k) CHECK(s.data(centre)[k] == before.data(centre)[k]);

    // In two groups nothing moves: two clumps.
    StrandSet t = before;
    st = applyGroomControls(t, g, {0u, 1u});
    CHECK(st.clumps == 2);
    CHECK(t.positions == before.positions);

    // A hair bent away (a parting) is not pulled into a straight centre's clump.
    StrandSet v;
    addStraight(v, Vec3f(0.f, 0.f, 0.f), Vec3f(0.f, 0.f, 1.f), 4.f, 9);
    addStraight(v, Vec3f(0.2f, 0.f, 0.f), Vec3f(1.f, 0.f, 0.f), 4.f, 9);
    const StrandSet vb = v;
    st = applyGroomControls(v, g);
    CHECK(st.clumped == 0);
    CHECK(v.positions == vb.positions);
}

TEST_CASE("curl, clumps and frizz do not depend on the thread count", "[groom]")
{
    std::mt19937 rng(2);
    std::uniform_real_distribution<float> u(0.f, 5.f);
    StrandSet s;
    for (int i = 0; i < 4000; ++i) addStraight(s, Vec3f(u(rng), u(rng), 0.f), Vec3f(0.1f, 0.f, 1.f).unit(), 3.f + 0.1f * u(rng), 12);
    GroomParams g;
    g.clump.radius = 0.4;
    g.curl.amplitude = 0.05;
    g.curl.frequency = 12.0;
    g.curl.frizz = 0.02;
    g.seed = 5;
    StrandSet a = s, b = s;
    const GroomStats sa = applyGroomControls(a, g, {}, true), sb = applyGroomControls(b, g, {}, false);
    CHECK(sa.clumps == sb.clumps);
    CHECK(sa.clumped == sb.clumped);
    CHECK(a.offsets == b.offsets);
    CHECK(a.positions == b.positions);
    for (std::size_t i = 0; i < a.numStrands(); ++i) CHECK(a.root(i) == s.root(i));
}

TEST_CASE("frizz is a random offset across the hair whose deviation grows to the given size at the tip", "[groom]")
{
    StrandSet s;
    for (int i = 0; i < 3000; ++i) addStraight(s, Vec3f(float(i), 0.f, 0.f), Vec3f(0.f, 0.f, 1.f), 2.f, 5);
    const StrandSet before = s;
    GroomParams g;
    g.curl.frizz = 0.1;
    applyGroomControls(s, g);
    double tip2 = 0.0, mid2 = 0.0, along = 0.0;
    for (std::size_t i = 0; i < s.numStrands(); ++i) {
        const Vec3f dt = s.tip(i) - before.tip(i), dm = s.data(i)[2] - before.data(i)[2];
        tip2 += double(dt.x()) * dt.x() + double(dt.y()) * dt.y();
        mid2 += double(dm.x()) * dm.x() + double(dm.y()) * dm.y();
        along += std::abs(double(dt.z()));
        CHECK(s.root(i) == before.root(i));
    }
    const double n = double(s.numStrands());
    CHECK(std::sqrt(tip2 / n) == Approx(0.1 * std::sqrt(2.0)).epsilon(0.05));   // two axes of deviation 0.1
    CHECK(std::sqrt(mid2 / n) == Approx(0.05 * std::sqrt(2.0)).epsilon(0.05));  // half way: half of it
    CHECK(along / n < 1e-6);                                                     // across the hair only
}

TEST_CASE("length cuts a hair at its share of the length; density keeps its share of the roots", "[groom]")
{
    StrandSet s;
    addStraight(s, Vec3f(0.f), Vec3f(0.f, 0.f, 1.f), 10.f, 11);
    addStraight(s, Vec3f(1.f, 0.f, 0.f), Vec3f(0.f, 0.f, 1.f), 10.f, 11);
    addStraight(s, Vec3f(2.f, 0.f, 0.f), Vec3f(0.f, 0.f, 1.f), 10.f, 11);
    s.thickness.assign(s.numVertices(), 1.f);
    for (std::size_t k = 0; k < 11; ++k) s.thickness[k] = float(k);
    CHECK(cutStrands(s, {0.55f, 1.f, 0.3f}) == 2);
    REQUIRE(s.size(0) == 7);  // 0..5 and the cut at 5.5
    CHECK(polylineLength(s.data(0), s.size(0)) == Approx(5.5).margin(1e-5));
    CHECK(s.thickness[6] == Approx(5.5f));
    CHECK(s.size(1) == 11);
    CHECK(s.size(2) == 4);  // 0..3, the cut on vertex 3
    CHECK(polylineLength(s.data(2), s.size(2)) == Approx(3.0).margin(1e-5));
    REQUIRE_THROWS_WITH(cutStrands(s, {0.f, 1.f, 1.f}), Contains("length 0 of strand 0: must be in (0, 1]"));

    const std::size_t R = 20000;
    const std::vector<char> half = rootsKept(R, std::vector<float>(R, 0.5f), {}, 3);
    std::size_t kept = 0;
    for (char k : half) kept += std::size_t(k);
    CHECK(kept > 9700);
    CHECK(kept < 10300);
    CHECK(rootsKept(R, std::vector<float>(R, 0.5f), {}, 3) == half);  // the same draw
    std::vector<float> lengths(R, 1.f);
    lengths[7] = 0.f;
    const std::vector<char> all = rootsKept(R, std::vector<float>(R, 1.f), lengths, 3);
    CHECK(std::count(all.begin(), all.end(), 0) == 1);
    CHECK(all[7] == 0);
    REQUIRE_THROWS_WITH(rootsKept(2, {0.5f, 1.5f}, {}, 0), Contains("density 1.5 at root 1: must be in [0, 1]"));
    REQUIRE_THROWS_WITH(rootsKept(2, {0.5f}, {}, 0), Contains("1 density values for 2 roots"));
    REQUIRE_THROWS_WITH(rootsKept(1, {}, {1.2f}, 0), Contains("length 1.2 at root 0: must be in [0, 1]"));
}

TEST_CASE("per-root values come from a number, a list, a mask grid or a painted mesh", "[groom]")
{
    const std::vector<Vec3d> roots{Vec3d(0.0), Vec3d(1.0, 0.0, 0.0), Vec3d(5.0, 5.0, 5.0)};
    CHECK(readRootValues("0.25", roots, "--density", "density") == std::vector<float>{0.25f, 0.25f, 0.25f});

    const std::string list = tempPath("values.txt");
    writeFileAtomic(list, "# density\n1, 0.5\n0\n", "test");
    CHECK(readRootValues(list, roots, "--density", "density") == std::vector<float>{1.f, 0.5f, 0.f});
    writeFileAtomic(list, "1 0.5\n", "test");
    REQUIRE_THROWS_WITH(readRootValues(list, roots, "--density", "density"), Contains("2 values for 3 roots: one per root"));
    writeFileAtomic(list, "1 0.5 x\n", "test");
    REQUIRE_THROWS_WITH(readRootValues(list, roots, "--density", "density"), Contains("line 1: 'x' is not a finite number"));

    // A float mask: 0.8 in a box around the first two roots, 0 (background) elsewhere; sampled trilinearly.
    openvdb::initialize();
    openvdb::FloatGrid::Ptr mask = openvdb::FloatGrid::create(0.f);
    mask->setTransform(openvdb::math::Transform::createLinearTransform(0.5));
    mask->fill(openvdb::CoordBBox(openvdb::Coord(-4), openvdb::Coord(6)), 0.8f, true);
    mask->setName("density");
    openvdb::FloatGrid::Ptr other = openvdb::FloatGrid::create(0.f);
    other->setName("aaa_other");
    other->setGridClass(openvdb::GRID_LEVEL_SET);
    const std::string vdb = tempPath("mask.vdb");
    writeVdbGrids(vdb, {other, mask}, "test");
    CHECK(readRootValues(vdb, roots, "--density", "density") == std::vector<float>{0.8f, 0.8f, 0.f});
    CHECK(readRootValues(vdb + ":density", roots, "--length", "length") == std::vector<float>{0.8f, 0.8f, 0.f});
    REQUIRE_THROWS_WITH(readRootValues(vdb + ":nope", roots, "--density", "density"), Contains("nope"));
    const std::string levelSetOnly = tempPath("surface.vdb");
    writeVdbGrids(levelSetOnly, {other}, "test");
    REQUIRE_THROWS_WITH(readRootValues(levelSetOnly, roots, "--length", "length"), Contains("no bool or float grid to use as --length"));

    // A value painted on mesh vertices: an exact hit is that vertex's value.
    TriangleMesh mesh;
    mesh.vertices = {Vec3f(0.f), Vec3f(1.f, 0.f, 0.f), Vec3f(0.f, 1.f, 0.f)};
    mesh.triangles = {{0u, 1u, 2u}};
    const VertexValueSampler painted(mesh, {0.1f, 0.9f, 0.5f}, "test");
    CHECK(painted.at(Vec3d(1.0, 0.0, 0.0)) == Approx(0.9));
    CHECK(painted.at(Vec3d(0.3, 0.3, 0.0)) > 0.1);
    CHECK(painted.at(Vec3d(0.3, 0.3, 0.0)) < 0.9);
    REQUIRE_THROWS_WITH(VertexValueSampler(mesh, {0.1f}, "m.ply"), Contains("m.ply: 1 values for 3 vertices"));
    REQUIRE_THROWS_WITH(readRootValues("head.ply", roots, "--density", "density"), Contains("head.ply:PROPERTY"));
    for (const std::string& f : {list, vdb, levelSetOnly}) std::filesystem::remove(f);
}

TEST_CASE("interpolate with density, length, clumps and curl: the hairs and the report", "[groom]")
{
    // Guides: straight hairs on a 5 x 5 patch; roots: 2,000 on the patch, half of them with
    // density 0 (x < 2) and a length share of 0.5 on the rest.
    StrandSet guides;
    for (int i = 0; i < 5; ++i)
        for (int j = 0; j < 5; ++j) addStraight(guides, Vec3f(float(i), float(j), 0.f), Vec3f(0.f, 0.f, 1.f), 4.f, 9);
    InterpolationGuides g;
    g.strands = &guides;
    InterpolationRoots roots;
    std::mt19937 rng(1);
    std::uniform_real_distribution<double> u(0.0, 4.0);
    for (int i = 0; i < 2000; ++i) {
        roots.positions.emplace_back(u(rng), u(rng), 0.0);
        roots.density.push_back(roots.positions.back().x() < 2.0 ? 0.f : 1.f);
        roots.length.push_back(0.5f);
    }
    InterpolateParams p;
    p.groom.clump.radius = 0.5;
    p.groom.curl.amplitude = 0.05;
    p.groom.curl.frequency = 10.0;
    const InterpolateResult r = interpolateGuides(g, roots, HeadObstacle::none(), p);
    std::size_t kept = 0;
    for (const Vec3d& x : roots.positions) kept += x.x() < 2.0 ? 0 : 1;
    CHECK(r.roots == 2000);
    CHECK(r.rootsDropped == 2000 - kept);
    REQUIRE(r.strands.numStrands() == kept);
    CHECK(r.cut == kept);
    CHECK(r.groom.clumps > 10);
    CHECK(r.groom.clumped > kept / 2);
    CHECK(r.groom.curled == kept);
    for (std::size_t i = 0; i < r.strands.numStrands(); ++i) {
        CHECK(r.strands.root(i).x() >= 2.f);
        CHECK(r.strands.tip(i).z() == Approx(2.0).margin(0.02));  // half of 4: cut before the curl, which winds across
    }
    roots.density.assign(roots.positions.size(), 0.f);
    REQUIRE_THROWS_WITH(interpolateGuides(g, roots, HeadObstacle::none(), p), Contains("leave none of the 2000 roots"));
    p.groom.curl.frequency = 0.0;
    REQUIRE_THROWS_WITH(interpolateGuides(g, roots, HeadObstacle::none(), p), Contains("--curl 0.05 needs --curl-frequency"));
}

TEST_CASE("group ids from a mask grid, a painted mesh property and a mesh's islands", "[groom]")
{
    // Two triangles apart (two islands, the second welded to a third by a shared position), with
    // a vertex property 'part'.
    const std::string ply = tempPath("islands.ply");
    writeFileAtomic(ply,
                    "ply\nformat ascii 1.0\nelement vertex 9\nproperty float x\nproperty float y\nproperty float z\nproperty float part\n"
                    "element face 3\nproperty list uchar int vertex_indices\nend_header\n"
                    "0 0 0 3\n1 0 0 3\n0 1 0 3\n"
                    "10 0 0 7\n11 0 0 7\n10 1 0 7\n"
                    "11 0 0 7\n12 0 0 7\n11 1 0 7\n"
                    "3 0 1 2\n3 3 4 5\n3 6 7 8\n",
                    "test");
    const std::vector<Vec3d> points{Vec3d(0.2, 0.2, 0.0), Vec3d(11.8, 0.1, 0.0), Vec3d(10.1, 0.9, 0.0), Vec3d(0.9, 0.0, 0.1)};
    CHECK(readRootIds(ply + ":islands", points, "--root-groups", "roots") == std::vector<std::int32_t>{0, 1, 1, 0});
    CHECK(readRootIds(ply + ":part", points, "--root-groups", "roots") == std::vector<std::int32_t>{3, 7, 7, 3});
    const std::string list = tempPath("ids.txt");
    writeFileAtomic(list, "1 2 3 4\n", "test");
    CHECK(readRootIds(list, points, "--root-groups", "roots") == std::vector<std::int32_t>{1, 2, 3, 4});
    // A float grid holding 0.5 is no group id.
    openvdb::initialize();
    openvdb::FloatGrid::Ptr g = openvdb::FloatGrid::create(0.5f);
    g->setName("groups");
    const std::string vdb = tempPath("groups.vdb");
    writeVdbGrids(vdb, {g}, "test");
    REQUIRE_THROWS_WITH(readRootIds(vdb, points, "--guide-groups", "guides"), Contains("the value 0.5 at guide 0 is not an integer group id"));
    for (const std::string& f : {ply, list, vdb}) std::filesystem::remove(f);
}

TEST_CASE("curl on hair lying on the head: flattened against it where it dips in, not turned away", "[groom]")
{
    // Guides lie on a sphere of radius 10 (0.05 above it) along meridians from near the top down
    // the side; new hair at roots between them, curled with an amplitude of 0.3. Every vertex the
    // curl moves inside the head is pushed out along the normal, so each tip stays within the
    // curl's reach of where the same hair ends without curl (a sweep would have turned the whole
    // rest of the strand off the head at the first dip).
    const double R = 10.05;
    StrandSet guides;
    for (int g = 0; g < 36; ++g) {
        const double phi = 2.0 * M_PI * g / 36.0;
        std::vector<Vec3f> p;
        for (int k = 0; k < 40; ++k) {
            const double theta = 0.2 + 1.2 * k / 39.0;  // from the crown down
            p.emplace_back(float(R * std::sin(theta) * std::cos(phi)), float(R * std::cos(theta)), float(R * std::sin(theta) * std::sin(phi)));
        }
        guides.addStrand(p);
    }
    InterpolationGuides g;
    g.strands = &guides;
    InterpolationRoots roots;
    for (int i = 0; i < 200; ++i) {
        const double phi = 2.0 * M_PI * (i + 0.5) / 200.0;
        roots.positions.emplace_back(R * std::sin(0.2) * std::cos(phi), R * std::cos(0.2), R * std::sin(0.2) * std::sin(phi));
    }
    const HeadObstacle head = HeadObstacle::sphere(Vec3d(0.0), 10.0);
    InterpolateParams plain, curled;
    curled.groom.curl.amplitude = 0.3;
    curled.groom.curl.frequency = 6.0;
    const InterpolateResult a = interpolateGuides(g, roots, head, plain), b = interpolateGuides(g, roots, head, curled);
    CHECK(b.enteringHead == 0);
    CHECK(b.groomPushedOut > 0);  // the curl did dip in
    REQUIRE(a.strands.numStrands() == b.strands.numStrands());
    for (std::size_t i = 0; i < a.strands.numStrands(); ++i) {
        CHECK((b.strands.tip(i) - a.strands.tip(i)).length() < 0.7f);  // the curl's reach, and what resampling moves
        CHECK(b.strands.root(i) == a.strands.root(i));
    }
}
