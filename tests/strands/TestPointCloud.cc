#include <vdbhair/strands/PointCloud.h>

#include <catch2/catch.hpp>

#include <cstdint>
#include <vector>

using namespace vdbhair;

TEST_CASE("PointKdTreeOf: the nearest points in float and in double, and a run-time dimension over rows", "[strands]")
{
    // Points on a line at 0, 1, 3, 7: from 2.9 the nearest are 3 (0.01) and 1 (3.61).
    const std::vector<Vec3d> pd{Vec3d(0, 0, 0), Vec3d(1, 0, 0), Vec3d(3, 0, 0), Vec3d(7, 0, 0)};
    const PointCloud cd{&pd};
    PointKdTree td(3, cd, nanoflann::KDTreeSingleIndexAdaptorParams(2));
    td.buildIndex();
    std::uint32_t idx[2];
    double d2[2];
    const double qd[3] = {2.9, 0.0, 0.0};
    REQUIRE(td.knnSearch(qd, 2, idx, d2) == 2);
    CHECK(idx[0] == 2);
    CHECK(idx[1] == 1);
    CHECK(d2[0] == Approx(0.01));
    CHECK(d2[1] == Approx(3.61));

    const std::vector<Vec3f> pf{Vec3f(0, 0, 0), Vec3f(0, 1, 0), Vec3f(0, 3, 0), Vec3f(0, 7, 0)};
    const PointCloudOf<Vec3f> cf{&pf};
    PointKdTreeOf<Vec3f> tf(3, cf, nanoflann::KDTreeSingleIndexAdaptorParams(2));
    tf.buildIndex();
    float f2[2];
    const float qf[3] = {0.f, 6.f, 0.f};
    REQUIRE(tf.knnSearch(qf, 2, idx, f2) == 2);
    CHECK(idx[0] == 3);
    CHECK(idx[1] == 2);
    CHECK(f2[0] == Approx(1.f));

    // Five 4D rows: the one nearest (1, 1, 1, 0.9) is row 3.
    const std::vector<float> rows{0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 1, 0, 1, 1, 1, 1, 2, 2, 2, 2};
    const RowCloud cr{rows.data(), 5, 4};
    RowKdTree tr(4, cr, nanoflann::KDTreeSingleIndexAdaptorParams(2));
    tr.buildIndex();
    const float qr[4] = {1.f, 1.f, 1.f, 0.9f};
    REQUIRE(tr.knnSearch(qr, 1, idx, f2) == 1);
    CHECK(idx[0] == 3);
    CHECK(f2[0] == Approx(0.01f));
}
