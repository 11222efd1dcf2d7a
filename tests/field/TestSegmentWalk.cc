#include "../TestUtil.h"

#include <vdbhair/SegmentWalk.h>

#include <random>

using namespace vdbhair;
using openvdb::Coord;
using openvdb::Vec3d;

TEST_CASE("walkSegment: every voxel the segment passes, with the lengths inside summing to the whole", "[field]")
{
    std::vector<std::pair<Coord, double>> pieces;
    auto record = [&](const Coord& c, double t0, double t1) { pieces.emplace_back(c, t1 - t0); };

    // Along x from the centre of voxel 0 to the centre of voxel 3: 0.5 + 1 + 1 + 0.5 of 3.
    walkSegment(Vec3d(0.0), Vec3d(3.0, 0.0, 0.0), record);
    REQUIRE(pieces.size() == 4);
    for (int i = 0; i < 4; ++i) REQUIRE(pieces[std::size_t(i)].first == Coord(i, 0, 0));
    REQUIRE(pieces[0].second == Approx(0.5 / 3.0));
    REQUIRE(pieces[1].second == Approx(1.0 / 3.0));
    REQUIRE(pieces[3].second == Approx(0.5 / 3.0));

    // Inside one voxel.
    pieces.clear();
    walkSegment(Vec3d(0.1, 0.1, 0.1), Vec3d(0.3, -0.2, 0.4), record);
    REQUIRE(pieces.size() == 1);
    REQUIRE(pieces[0].second == Approx(1.0));

    // Random segments: consecutive voxels are face neighbours, the walk ends in the end point's
    // voxel, and the pieces add up to the segment.
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(-20.0, 20.0);
    for (int trial = 0; trial < 200; ++trial) {
        const Vec3d a(u(rng), u(rng), u(rng)), b(u(rng), u(rng), u(rng));
        pieces.clear();
        walkSegment(a, b, record);
        CAPTURE(trial, a, b);
        double sum = 0.0;
        for (std::size_t k = 0; k < pieces.size(); ++k) {
            sum += pieces[k].second;
            REQUIRE(pieces[k].second >= 0.0);
            if (k) {
                const Coord d = pieces[k].first - pieces[k - 1].first;
                REQUIRE(std::abs(d.x()) + std::abs(d.y()) + std::abs(d.z()) == 1);
            }
        }
        REQUIRE(sum == Approx(1.0).epsilon(1e-12));
        REQUIRE(pieces.front().first == Coord::round(a));
        REQUIRE(pieces.back().first == Coord::round(b));
        REQUIRE(pieces.size() <= segmentVoxelBound(a, b));
    }
}
