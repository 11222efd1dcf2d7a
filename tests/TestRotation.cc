#include <vdbhair/Rotation.h>

#include <catch2/catch.hpp>

#include <cmath>

using namespace vdbhair;

namespace {

constexpr double kPi = 3.14159265358979323846;

bool near(const Vec3d& a, const Vec3d& b, double tol = 1e-14) { return (a - b).length() <= tol; }

} // namespace

TEST_CASE("rotateAbout: a quarter turn about z takes x to y; a third of a turn about (1,1,1) permutes the axes", "[core]")
{
    const Vec3d x(1, 0, 0), y(0, 1, 0), z(0, 0, 1);
    CHECK(near(rotateAbout(x, z, kPi / 2), y));
    CHECK(near(rotateAbout(y, z, kPi / 2), -x));
    CHECK(near(rotateAbout(z, z, 0.7), z));
    CHECK(near(rotateAbout(x, z, 0.0, 1.0), y));  // cosine and sine given
    // About the unit diagonal by 120 degrees: x -> y -> z -> x, so (1, 2, 3) -> (3, 1, 2).
    const Vec3d d = Vec3d(1, 1, 1) / std::sqrt(3.0);
    CHECK(near(rotateAbout(Vec3d(1, 2, 3), d, 2.0 * kPi / 3.0), Vec3d(3, 1, 2)));
    // The same numbers as OpenVDB's rotation matrix, to rounding (OpenVDB's acts on row vectors).
    const Vec3d axis = Vec3d(0.3, -0.5, 0.8).unitSafe(), v(0.2, 1.7, -0.4);
    const openvdb::math::Mat3d R = openvdb::math::rotation<openvdb::math::Mat3d>(axis, 1.1);
    CHECK(near(rotateAbout(v, axis, 1.1), R.transform(v)));
}

TEST_CASE("rotateByVector: the axis is the vector's direction, the angle its length; zero leaves the vector", "[core]")
{
    CHECK(near(rotateByVector(Vec3d(1, 0, 0), Vec3d(0, 0, kPi / 2)), Vec3d(0, 1, 0)));
    CHECK(near(rotateByVector(Vec3d(0, 2, 0), Vec3d(kPi, 0, 0)), Vec3d(0, -2, 0)));
    const Vec3d v(0.3, -0.2, 0.9);
    CHECK(rotateByVector(v, Vec3d(0.0)) == v);
}

TEST_CASE("halfTurn: the reflection through the axis", "[core]")
{
    const Vec3d k = Vec3d(1, 2, 2) / 3.0;
    CHECK(near(halfTurn(k, k), k));
    CHECK(near(halfTurn(Vec3d(2, -1, 0), k), Vec3d(-2, 1, 0)));  // perpendicular to k: reversed
    CHECK(near(halfTurn(Vec3d(0.5, 0.1, -0.7), k), rotateAbout(Vec3d(0.5, 0.1, -0.7), k, kPi)));
}

TEST_CASE("shortest rotation: takes a onto b, keeps a x b, turns by the angle between them", "[core]")
{
    const Vec3d a = Vec3d(1, 2, 2) / 3.0, b = Vec3d(2, -1, 2) / 3.0;  // a . b = 4 / 9
    const Vec3d n = a.cross(b), nHat = n.unitSafe();
    Vec3d axis;
    double c = 0.0, s = 0.0;
    REQUIRE(shortestRotation(a, b, axis, c, s));
    CHECK(near(axis, nHat));
    CHECK(c == Approx(4.0 / 9.0).epsilon(1e-15));
    CHECK(s == Approx(std::sqrt(65.0) / 9.0).epsilon(1e-15));

    CHECK(near(rotateOnto(a, b, a, Vec3d(0, 0, 1)), b));
    CHECK(near(rotateOnto(a, b, n, Vec3d(0, 0, 1)), n));
    CHECK(near(rotateOnto(a, b, Vec3d(3, 0, -1), Vec3d(0, 0, 1)), rotateAbout(Vec3d(3, 0, -1), nHat, std::acos(4.0 / 9.0))));

    const Vec3d r = rotationVectorBetween(a, b);
    CHECK(near(r, nHat * std::acos(4.0 / 9.0)));
    CHECK(near(rotateByVector(a, r), b));

    const openvdb::math::Mat3d M = rotationMatrixBetween(a, b);
    CHECK(near(M.transform(a), b));
    CHECK(near(M.transform(n), n));
}

TEST_CASE("shortest rotation: parallel directions leave a vector as it is; opposite ones take the caller's half turn", "[core]")
{
    const Vec3d a = Vec3d(1, 2, 2) / 3.0, v(0.4, -0.3, 0.8), k = Vec3d(2, -1, 0) / std::sqrt(5.0);
    Vec3d axis;
    double c = 0.0, s = 0.0;
    CHECK_FALSE(shortestRotation(a, a, axis, c, s));
    CHECK(c == Approx(1.0));
    CHECK_FALSE(shortestRotation(a, -a, axis, c, s));
    CHECK(c == Approx(-1.0));
    CHECK(rotateOnto(a, a, v, k) == v);
    CHECK(near(rotateOnto(a, -a, a, k), -a));
    CHECK(near(rotateOnto(a, -a, v, k), halfTurn(v, k)));
    CHECK(rotationVectorBetween(a, a) == Vec3d(0.0));
    CHECK(rotationVectorBetween(a, -a) == Vec3d(0.0));  // a half turn has no one axis
}
