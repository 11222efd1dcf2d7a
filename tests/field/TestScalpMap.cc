#include <vdbhair/scalp/ScalpSurface.h>
#include <vdbhair/field/ScalpMap.h>

#include <catch2/catch.hpp>

using namespace vdbhair;

namespace {
void checkFrame(const ScalpFrame& f)
{
    CHECK(f.t.length() == Approx(1.0).margin(1e-9));
    CHECK(f.n.length() == Approx(1.0).margin(1e-9));
    CHECK(f.b.length() == Approx(1.0).margin(1e-9));
    CHECK(std::abs(f.t.dot(f.n)) < 1e-9);
    CHECK(std::abs(f.t.dot(f.b)) < 1e-9);
    CHECK((f.t.cross(f.n) - f.b).length() < 1e-9);  // right-handed: t x n = b (x x y = z)
}
} // namespace

TEST_CASE("ScalpMap: the sphere round-trips and its frames are radial", "[field]")
{
    ScalpSphere s;
    s.center = Vec3d(0.3, -0.2, 0.1);
    s.radius = 2.0;
    const ScalpMap map(s);
    CHECK_FALSE(map.hasSurface());
    for (int i = 0; i < 200; ++i) {
        const double az = 0.37 * i, el = 0.1 + 1.3 * double(i % 17) / 17.0;
        const double h = 0.05 * (i % 7);
        const Vec3d p = s.center + Vec3d(std::cos(el) * std::cos(az), std::sin(el), std::cos(el) * std::sin(az)) * s.radius * (1 + h);
        const Vec3d uvw = map.toScalp(p);
        CAPTURE(i, p, uvw);
        CHECK(uvw.z() == Approx(h).margin(1e-9));
        CHECK((map.toWorld(uvw) - p).length() < 1e-9);
        const ScalpFrame f = map.frame(uvw.x(), uvw.y());
        checkFrame(f);
        CHECK((f.n - (p - s.center).unitSafe()).length() < 1e-9);
    }
    // The top of the head: the identity frame (R = I when the normal is +y).
    const ScalpFrame top = map.frame(0.5 * M_PI, 0.5 * M_PI);
    CHECK((top.t - Vec3d(1, 0, 0)).length() < 1e-9);
    CHECK((top.b - Vec3d(0, 0, 1)).length() < 1e-9);
}

TEST_CASE("ScalpMap: a level-set scalp is measured along the rays (d, w, normals)", "[field]")
{
    // A scalp of radius 1.2 parameterized by the unit sphere at the same centre: d = 1.2 everywhere.
    ScalpParams params;
    params.voxelSize = 0.02;
    const Vec3d c(0.1, 0.2, -0.1);
    auto surface = scalpFromSphere(c, 1.2, params);
    ScalpSphere s;
    s.center = c;
    s.radius = 1.0;
    const ScalpMap map(s, *surface, 64);
    CHECK(map.hasSurface());
    CHECK(map.misses() == 0);
    for (int i = 0; i < 100; ++i) {
        const double az = 0.61 * i, el = -0.3 + 1.7 * double(i % 13) / 13.0;
        const Vec3d dir(std::cos(el) * std::cos(az), std::sin(el), std::cos(el) * std::sin(az));
        const Vec3d p = c + dir * 1.5;
        const Vec3d uvw = map.toScalp(p);
        CAPTURE(i, uvw);
        CHECK(map.scalpDistance(uvw.x(), uvw.y()) == Approx(1.2).margin(0.1 * params.voxelSize));
        CHECK(uvw.z() == Approx(0.3).margin(0.1 * params.voxelSize));
        CHECK((map.toWorld(uvw) - p).length() < 1e-9);  // exact inverse whatever d is
        const Vec3d onScalp = map.projectToScalp(p);
        CHECK((onScalp - c).length() == Approx(1.2).margin(0.1 * params.voxelSize));
        const ScalpFrame f = map.frame(uvw.x(), uvw.y());
        checkFrame(f);
        CHECK(f.n.dot(dir) > std::cos(1.0 * M_PI / 180.0));
    }
}

TEST_CASE("ScalpMap: a centre outside the scalp is refused", "[field]")
{
    ScalpParams params;
    params.voxelSize = 0.05;
    auto surface = scalpFromSphere(Vec3d(0.0), 1.0, params);
    ScalpSphere s;
    s.center = Vec3d(3.0, 0.0, 0.0);
    CHECK_THROWS_WITH(ScalpMap(s, *surface, 32), Catch::Contains("not inside the scalp surface"));
    s.center = Vec3d(0.0);
    CHECK_THROWS_WITH(ScalpMap(s, *surface, 4), Catch::Contains("resolution 4"));
}

TEST_CASE("moveToScalp: the same head is the identity, a turn is a rigid rotation, a larger head scales", "[field]")
{
    ScalpSphere s;
    s.center = Vec3d(0.3, -0.2, 0.1);
    s.radius = 2.0;
    s.up = Vec3d(0.0, 1.0, 0.0);
    const ScalpMap a(s);
    // Strands on the upper half, bent in all directions.
    StrandSet hair;
    for (int i = 0; i < 60; ++i) {
        const double az = 0.41 * i, el = 0.2 + 1.2 * double(i % 11) / 11.0;
        const Vec3d n(std::cos(el) * std::cos(az), std::sin(el), std::cos(el) * std::sin(az));
        std::vector<Vec3f> pts;
        for (int k = 0; k < 12; ++k) {
            const double t = 0.1 * k;
            pts.emplace_back(s.center + n * s.radius * (1.0 + 0.02 + 0.3 * t) + Vec3d(0.2 * t * t, -0.5 * t, 0.1 * std::sin(3 * t)));
        }
        hair.addStrand(pts);
    }
    const auto maxDiff = [](const StrandSet& x, const std::vector<Vec3d>& y) {
        double m = 0.0;
        for (std::size_t k = 0; k < y.size(); ++k) m = std::max(m, (Vec3d(x.positions[k]) - y[k]).length());
        return m;
    };
    std::vector<Vec3d> same, rotated, scaled;
    const double turn = 0.7, c = std::cos(turn), sn = std::sin(turn);
    for (const Vec3f& p : hair.positions) {
        const Vec3d q = Vec3d(p) - s.center;
        same.push_back(Vec3d(p));
        rotated.push_back(s.center + Vec3d(c * q.x() + sn * q.z(), q.y(), -sn * q.x() + c * q.z()));
        scaled.push_back(Vec3d(1, 2, 3) + q * 1.5);
    }
    CHECK(maxDiff(moveToScalp(hair, a, a), same) < 1e-5);
    const StrandSet turned = moveToScalp(hair, a, a, turn);
    CHECK(maxDiff(turned, rotated) < 1e-5);
    CHECK(maxDiff(moveToScalp(turned, a, a, -turn), same) < 1e-5);
    ScalpSphere big = s;
    big.center = Vec3d(1, 2, 3);
    big.radius = 3.0;
    const StrandSet moved = moveToScalp(hair, a, ScalpMap(big));
    CHECK(maxDiff(moved, scaled) < 1e-5);
    CHECK(moved.offsets == hair.offsets);
    // Onto a level-set scalp: roots land on it (w kept: 0.02 radii above it).
    ScalpParams sp;
    sp.voxelSize = 0.05;
    const openvdb::FloatGrid::Ptr ball = scalpFromSphere(big.center, big.radius, sp);
    const ScalpMap onBall(big, *ball);
    const StrandSet landed = moveToScalp(hair, a, onBall);
    for (std::size_t i = 0; i < landed.numStrands(); ++i)
        CHECK((Vec3d(landed.root(i)) - big.center).length() == Approx(big.radius * 1.02).epsilon(0.01));
}
