#include "../TestUtil.h"

#include <vdbhair/strands/Frames.h>

using namespace vdbhair;

namespace {
void requireOrthonormal(const Frame& f)
{
    REQUIRE(f.t.length() == Approx(1.0).epsilon(1e-5));
    REQUIRE(f.n.length() == Approx(1.0).epsilon(1e-5));
    REQUIRE(f.t.dot(f.n) == Approx(0.0).margin(1e-5));
    REQUIRE((f.t.cross(f.n) - f.b).length() == Approx(0.0).margin(1e-5));
}
} // namespace

TEST_CASE("frenetFrames: a helix's analytic Frenet frame", "[strands]")
{
    const double r = 2.0, c = 0.5;
    const std::size_t n = 301;  // coarse enough that float positions do not dominate the error
    const double tMax = 3.0 * M_PI;
    const auto pts = test::helix(r, c, tMax, n);
    std::vector<Frame> frames(n);
    frenetFrames(pts.data(), n, frames.data());
    const double w = std::sqrt(r * r + c * c);
    for (std::size_t i = 1; i + 1 < n; i += 13) {
        const double t = tMax * double(i) / double(n - 1);
        const Vec3f T(float(-r * std::sin(t) / w), float(r * std::cos(t) / w), float(c / w));
        const Vec3f N(float(-std::cos(t)), float(-std::sin(t)), 0.f);
        const Vec3f B(float(c * std::sin(t) / w), float(-c * std::cos(t) / w), float(r / w));
        CAPTURE(i);
        requireOrthonormal(frames[i]);
        REQUIRE((frames[i].t - T).length() == Approx(0.0).margin(1e-4));
        REQUIRE((frames[i].n - N).length() == Approx(0.0).margin(1e-3));
        REQUIRE((frames[i].b - B).length() == Approx(0.0).margin(1e-3));
    }
}

TEST_CASE("frenetFrames: straight parts carry the last normal; a straight strand takes a stable one", "[strands]")
{
    std::vector<Vec3f> pts{Vec3f(0.f), Vec3f(0.f, 0.f, 1.f), Vec3f(0.f, 0.f, 2.f), Vec3f(0.f, 0.f, 3.f)};
    std::vector<Frame> f(pts.size());
    frenetFrames(pts.data(), pts.size(), f.data());
    for (const Frame& fr : f) {
        requireOrthonormal(fr);
        REQUIRE(fr.t == Vec3f(0.f, 0.f, 1.f));
        REQUIRE(fr.n == f[0].n);
    }
    REQUIRE((f[0].n - perpendicularTo(Vec3f(0.f, 0.f, 1.f))).length() == 0.f);

    // An L shape: a bend in the middle, straight on both sides.
    pts = {Vec3f(0.f), Vec3f(1.f, 0.f, 0.f), Vec3f(2.f, 0.f, 0.f), Vec3f(2.f, 1.f, 0.f), Vec3f(2.f, 2.f, 0.f), Vec3f(2.f, 3.f, 0.f)};
    f.resize(pts.size());
    frenetFrames(pts.data(), pts.size(), f.data());
    for (const Frame& fr : f) {
        requireOrthonormal(fr);
        REQUIRE(std::abs(fr.b.z()) == Approx(1.0).epsilon(1e-5));  // the plane of the bend
    }
}

TEST_CASE("parallelTransportFrames: rotation-minimizing along a helix", "[strands]")
{
    const std::size_t n = 401;
    const auto pts = test::helix(1.0, 0.4, 4.0 * M_PI, n);
    std::vector<Frame> f(n);
    parallelTransportFrames(pts.data(), n, f.data());
    for (std::size_t i = 0; i + 1 < n; ++i) {
        requireOrthonormal(f[i]);
        // No rotation about the tangent: the normal's change has no binormal component
        // (measured against the mean binormal of the step, which cancels the second-order term).
        const Vec3f dn = f[i + 1].n - f[i].n;
        REQUIRE(dn.dot(f[i].b + f[i + 1].b) == Approx(0.0).margin(1e-5));  // Frenet turns 1.2e-2 a step
    }
    // Relative to the Frenet frame it turns back by the total torsion: angle(s) = -(integral of tau ds).
    std::vector<Frame> fr(n);
    frenetFrames(pts.data(), n, fr.data());
    const double tau = 0.4 / (1.0 + 0.16), ds = 4.0 * M_PI * std::sqrt(1.16) / double(n - 1);
    auto angleAt = [&](std::size_t i) { return std::atan2(f[i].n.dot(fr[i].b), f[i].n.dot(fr[i].n)); };
    for (std::size_t i = 1; i + 1 < n; i += 40) {
        CAPTURE(i);
        const double turned = angleAt(i) - angleAt(1);
        REQUIRE(std::abs(std::remainder(turned + tau * ds * double(i - 1), 2.0 * M_PI)) < 5e-3);
    }
}

TEST_CASE("parallelTransportFrames: a planar curve keeps its normal in the plane", "[strands]")
{
    const auto pts = test::circleArc(1.0, 5.0, 200);
    std::vector<Frame> f(pts.size());
    parallelTransportFrames(pts.data(), pts.size(), Vec3f(0.f, 0.f, 1.f), f.data());
    for (const Frame& fr : f) REQUIRE((fr.n - Vec3f(0.f, 0.f, 1.f)).length() == Approx(0.0).margin(1e-5));
}
