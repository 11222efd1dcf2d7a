#include <vdbhair/strands/PointGrid.h>

#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

using namespace vdbhair;

namespace {

/// Clouds the grid must handle: spread in a box, on a thin shell (hair over a head: most cells
/// empty), flat (one axis of zero extent), on a line, with duplicates, and a single point.
std::vector<std::vector<Vec3f>> clouds()
{
    std::mt19937 rng(17);
    std::uniform_real_distribution<float> u(-1.f, 1.f);
    std::vector<std::vector<Vec3f>> out(6);
    for (int i = 0; i < 3000; ++i) out[0].emplace_back(u(rng) * 3.f, u(rng), u(rng) * 0.5f);
    for (int i = 0; i < 3000; ++i) {
        Vec3f d(u(rng), u(rng), u(rng));
        if (d.length() < 1e-3f) continue;
        out[1].push_back(d.unit() * (10.f + 0.05f * u(rng)));
    }
    for (int i = 0; i < 2000; ++i) out[2].emplace_back(u(rng), u(rng), 7.f);
    for (int i = 0; i < 500; ++i) out[3].emplace_back(float(i) * 0.01f, 0.f, 0.f);
    for (int i = 0; i < 1000; ++i) out[4].emplace_back(float(i % 7), float(i % 3), 0.f);  // 21 distinct points, repeated
    out[5].emplace_back(1.f, 2.f, 3.f);
    return out;
}

double d2(const Vec3d& p, const Vec3f& q) { return (p - Vec3d(q.x(), q.y(), q.z())).lengthSqr(); }

} // namespace

TEST_CASE("PointGrid: radius queries and nearest points against brute force", "[strands]")
{
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(-12.0, 12.0);
    for (const std::vector<Vec3f>& pts : clouds()) {
        CAPTURE(pts.size());
        const PointGrid grid(pts);
        REQUIRE(grid.size() == pts.size());
        for (int k = 0; k < 300; ++k) {
            // Queries near the points (jittered copies) and anywhere in the box around them.
            const Vec3f& base = pts[std::size_t(k * 7919) % pts.size()];
            const Vec3d p = k % 2 ? Vec3d(u(rng), u(rng), u(rng)) : Vec3d(base.x(), base.y(), base.z()) + Vec3d(u(rng), u(rng), u(rng)) * 0.01;
            // Nearest: the smallest distance and, among ties, the smallest index.
            std::uint32_t want = 0;
            double wantD2 = std::numeric_limits<double>::infinity();
            for (std::size_t i = 0; i < pts.size(); ++i) {
                if (d2(p, pts[i]) < wantD2) {
                    wantD2 = d2(p, pts[i]);
                    want = std::uint32_t(i);
                }
            }
            double got2 = std::numeric_limits<double>::infinity();
            CHECK(grid.nearest(p, got2) == want);
            CHECK(got2 == wantD2);
            // With a bound from some other point: the same answer.
            double bounded2 = d2(p, pts[std::size_t(k) % pts.size()]);
            CHECK(grid.nearest(p, bounded2) == want);
            CHECK(bounded2 == wantD2);
            // Every point within a radius, once.
            const double radius = k % 3 == 0 ? 0.0 : (k % 3 == 1 ? 0.05 : 1.5);
            std::vector<int> seen(pts.size(), 0);
            grid.forEachWithin(p, radius, [&](std::uint32_t i, double e2) {
                CHECK(e2 == d2(p, pts[i]));
                ++seen[i];
                return true;
            });
            for (std::size_t i = 0; i < pts.size(); ++i) {
                const int expected = d2(p, pts[i]) <= radius * radius ? 1 : 0;
                if (seen[i] != expected) FAIL_CHECK("point " << i << " seen " << seen[i] << " times, expected " << expected);
            }
        }
    }
    // Stopping: the visit's false ends the search.
    const std::vector<Vec3f> line = clouds()[3];
    const PointGrid grid(line);
    int visits = 0;
    CHECK_FALSE(grid.forEachWithin(Vec3d(2.5, 0.0, 0.0), 1.0, [&](std::uint32_t, double) { return ++visits < 3; }));
    CHECK(visits == 3);
    double none = std::numeric_limits<double>::infinity();
    CHECK(PointGrid(std::vector<Vec3f>()).nearest(Vec3d(0.0), none) == ~0u);
}
