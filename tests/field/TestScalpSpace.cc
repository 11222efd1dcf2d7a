#include "../TestUtil.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/field/FieldMapping.h>
#include <vdbhair/field/ScalpSpace.h>

#include <random>

using namespace vdbhair;

TEST_CASE("worldToScalp / scalpToWorld: Wang et al. Eq. 1 and 2 invert each other", "[field]")
{
    ScalpSphere s;
    s.center = Vec3d(1.0, -2.0, 3.0);
    s.radius = 7.5;
    // The top of the scalp is u = v = pi/2, w = 0; w is the height in radii.
    const Vec3d top = worldToScalp(s, s.center + Vec3d(0.0, s.radius, 0.0));
    REQUIRE(top.x() == Approx(M_PI / 2));
    REQUIRE(top.y() == Approx(M_PI / 2));
    REQUIRE(top.z() == Approx(0.0).margin(1e-12));
    REQUIRE(worldToScalp(s, s.center + Vec3d(0.0, 2.0 * s.radius, 0.0)).z() == Approx(1.0));
    // u is the angle from +x seen from the south pole: the +x side of the equator is u = pi/4.
    REQUIRE(worldToScalp(s, s.center + Vec3d(s.radius, 0.0, 0.0)).x() == Approx(M_PI / 4));

    std::mt19937 rng(5);
    std::uniform_real_distribution<double> a(-1.0, 1.0);
    for (int up = 0; up < 3; ++up) {
        s.up = up == 0 ? Vec3d(0, 1, 0) : up == 1 ? Vec3d(0, 0, 1) : Vec3d(1, 1, 0).unit();
        for (int i = 0; i < 500; ++i) {
            Vec3d d(a(rng), a(rng), a(rng));
            if (d.dot(s.up) < -0.5 * d.length()) continue;  // away from the singular south pole
            const Vec3d p = s.center + 12.0 * d;
            const Vec3d back = scalpToWorld(s, worldToScalp(s, p));
            CAPTURE(up, i, p, back);
            REQUIRE((back - p).length() < 1e-9 * 12.0 + 1e-9);
        }
    }
}

TEST_CASE("fitScalpSphere: recovers a sphere from points on a cap", "[field]")
{
    std::vector<Vec3f> pts;
    std::mt19937 rng(2);
    std::uniform_real_distribution<double> a(0.0, 2.0 * M_PI), c(0.2, 1.0);
    for (int i = 0; i < 400; ++i) {
        const double phi = a(rng), y = c(rng), r = std::sqrt(1.0 - y * y);
        pts.emplace_back(float(4.0 + 9.0 * r * std::cos(phi)), float(-1.0 + 9.0 * y), float(2.0 + 9.0 * r * std::sin(phi)));
    }
    const ScalpSphere s = fitScalpSphere(pts);
    REQUIRE(s.radius == Approx(9.0).epsilon(1e-4));
    REQUIRE((s.center - Vec3d(4.0, -1.0, 2.0)).length() < 1e-3);
    REQUIRE_THROWS_AS(fitScalpSphere(std::vector<Vec3f>(3, Vec3f(0.f))), ValueError);
    std::vector<Vec3f> plane;
    for (int i = 0; i < 10; ++i) plane.emplace_back(float(i), float(i * i % 7), 0.f);
    REQUIRE_THROWS_AS(fitScalpSphere(plane), ValueError);
}

TEST_CASE("FieldMapping::fromGrid: scalp metadata under vdbhair_ keys and the older vdbhair: keys", "[field]")
{
    for (const char* prefix : {"vdbhair_", "vdbhair:"}) {
        CAPTURE(prefix);
        openvdb::FloatGrid grid;
        const std::string p(prefix);
        grid.insertMeta(p + "space", openvdb::StringMetadata("scalp"));
        grid.insertMeta(p + "scalp_center", openvdb::Vec3DMetadata(openvdb::Vec3d(1, 2, 3)));
        grid.insertMeta(p + "scalp_radius", openvdb::DoubleMetadata(4.0));
        grid.insertMeta(p + "scalp_up", openvdb::Vec3DMetadata(openvdb::Vec3d(0, 1, 0)));
        const FieldMapping m = FieldMapping::fromGrid(grid);
        REQUIRE(m.space() == FieldSpace::Scalp);
        REQUIRE(m.scalp().radius == 4.0);
        REQUIRE(m.scalp().center == Vec3d(1, 2, 3));
    }
}
