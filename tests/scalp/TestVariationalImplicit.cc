#include "../TestUtil.h"
#include "ScalpTestUtil.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/Random.h>
#include <vdbhair/scalp/VariationalImplicit.h>

using namespace vdbhair;
using Catch::Matchers::Contains;

TEST_CASE("VariationalImplicit: interpolates its constraints with the right sign", "[scalp]")
{
    for (const double r : {0.01, 1.0, 250.0}) {
        const Vec3d c(3.0 * r, -r, 0.5);
        const OrientedPoints pts = test::fibonacciSphere(300, c, r);
        const VariationalImplicit f(pts.positions, pts.normals);
        CAPTURE(r, f.modelSize(), f.relativeResidual());
        REQUIRE(f.numCenters() == 600);
        double worst = 0.0;
        for (std::size_t i = 0; i < f.centers().size(); ++i) worst = std::max(worst, std::abs(f.value(f.centers()[i]) - f.targets()[i]));
        CHECK(worst < 1e-6 * f.modelSize());
        CHECK(f.offset() == Approx(0.01 * f.modelSize()));
        CHECK(f.value(c) < 0.0);                        // inside
        CHECK(f.value(c + Vec3d(0, 2.0 * r, 0)) > 0.0);  // outside
        CHECK(f.value(c + Vec3d(1.5 * r, 0, 0)) > 0.0);
        // Compare against the sphere the points came from: the zero set stays within 1 % of r.
        Rng rng(7);
        for (int k = 0; k < 200; ++k) {
            double a, b, e, unused;
            rng.normalPair(a, b);
            rng.normalPair(e, unused);
            Vec3d u(a, b, e);
            u.normalize();
            Vec3d g;
            const double v = f.valueAndGradient(c + u * r, g);
            CAPTURE(k, v, g.length());
            CHECK(std::abs(v) / g.length() < 0.01 * r);
            CHECK(g.dot(u) > 0.0);  // the gradient points outward
        }
    }
}

TEST_CASE("VariationalImplicit: refuses undetermined inputs", "[scalp]")
{
    const OrientedPoints pts = test::fibonacciSphere(4, Vec3d(0.0), 1.0);
    CHECK_THROWS_WITH(VariationalImplicit(pts.positions, pts.normals), Contains("4 constraint points; the implicit needs at least 5"));
    std::vector<Vec3f> plane, up;
    for (int i = 0; i < 6; ++i) {
        plane.emplace_back(float(i % 3), float(i / 3), 2.f);
        up.emplace_back(0.f, 0.f, 1.f);
    }
    CHECK_THROWS_AS(VariationalImplicit(plane, up), ValueError);
    CHECK_THROWS_WITH(VariationalImplicit(plane, up), Contains("lie on one plane"));
    std::vector<Vec3f> fewNormals(up.begin(), up.begin() + 3);
    CHECK_THROWS_WITH(VariationalImplicit(plane, fewNormals), Contains("3 normals for 6 points"));
}
