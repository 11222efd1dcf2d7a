#include "../TestUtil.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/io/AxisName.h>
#include <vdbhair/io/ConvertStrands.h>

using namespace vdbhair;

namespace {

StrandSet oneStrand(const std::vector<Vec3f>& points)
{
    StrandSet s;
    s.addStrand(points);
    return s;
}

} // namespace

TEST_CASE("rotateUpToY: each named up axis lands on +Y, the frame kept right-handed", "[io]")
{
    const Vec3f x(1.f, 0.f, 0.f), y(0.f, 1.f, 0.f), z(0.f, 0.f, 1.f);
    for (const std::string& name : axisNames()) {
        CAPTURE(name);
        const Vec3d up = axisFromName(name, "up");
        StrandSet s = oneStrand({Vec3f(float(up.x()), float(up.y()), float(up.z())), x, y, z});
        rotateUpToY(s, up);
        CHECK(s.positions[0] == y);
        // A rotation: the images of x, y and z are still a right-handed orthonormal frame.
        CHECK(s.positions[1].cross(s.positions[2]) == s.positions[3]);
        CHECK(s.upAxis == (name == "y" ? '\0' : 'Y'));
    }
}

TEST_CASE("axisFromName: the six names and an error naming the option and the choices", "[io]")
{
    for (const std::string& name : axisNames()) CHECK(axisName(axisFromName(name, "up")) == name);
    REQUIRE_THROWS_WITH(axisFromName("w", "--up"), "--up 'w' is not one of x, y, z, -x, -y, -z");
    REQUIRE_THROWS_AS(axisName(Vec3d(1.0, 1.0, 0.0)), ValueError);
}

TEST_CASE("convertStrands: scale, then the up axis onto +Y, then resampling", "[io]")
{
    StrandSet s = oneStrand({Vec3f(0.f), Vec3f(0.f, 0.f, 1.f), Vec3f(0.f, 0.f, 2.f)});
    ConvertParams p;
    p.scale = 2.0;
    p.up = Vec3d(0.0, 0.0, 1.0);
    p.resample = 5;
    convertStrands(s, p);
    REQUIRE(s.numVertices() == 5);
    for (std::size_t i = 0; i < 5; ++i) {
        CAPTURE(i);
        CHECK(s.positions[i].x() == Approx(0.0).margin(1e-6));
        CHECK(s.positions[i].y() == Approx(double(i)).margin(1e-5));  // 4 units long after the scale, along +Y
        CHECK(s.positions[i].z() == Approx(0.0).margin(1e-6));
    }
}

TEST_CASE("ConvertParams::validate: resample 1 and scale 0 named with their values and rules", "[io]")
{
    ConvertParams p;
    REQUIRE_NOTHROW(p.validate());
    p.resample = 1;
    REQUIRE_THROWS_WITH(p.validate(), "resample 1: a strand needs at least 2 vertices (0 keeps them)");
    p = ConvertParams{};
    p.scale = 0.0;
    REQUIRE_THROWS_WITH(p.validate(), "scale 0: must be finite and non-zero");
    StrandSet s = oneStrand({Vec3f(0.f), Vec3f(1.f)});
    REQUIRE_THROWS_AS(convertStrands(s, p), ValueError);
}
