#include "../TestUtil.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/Random.h>
#include <vdbhair/field/FieldSampler.h>
#include <vdbhair/field/Refine.h>
#include <vdbhair/field/StreamlineTracer.h>
#include <vdbhair/field/TangentAngles.h>
#include <vdbhair/field/TangentField.h>
#include <vdbhair/io/StrandIO.h>
#include <vdbhair/strands/Measures.h>

#include <tbb/global_control.h>

#include <algorithm>
#include <cstring>
#include <random>

using namespace vdbhair;
using Catch::Matchers::Contains;

namespace {

/// Concentric circles about the z axis (radii r0, r0 + dr, ...), stacked in z, sampled finely.
StrandSet concentricCircles(double r0, double dr, int rings, int layers, double arc)
{
    StrandSet s;
    for (int l = 0; l < layers; ++l) {
        for (int k = 0; k < rings; ++k) {
            const double r = r0 + dr * k;
            std::vector<Vec3f> pts;
            const int n = int(arc * r / 0.05) + 2;
            for (int i = 0; i < n; ++i) {
                const double a = arc * double(i) / double(n - 1);
                pts.emplace_back(float(r * std::cos(a)), float(r * std::sin(a)), float(0.2 * l));
            }
            s.addStrand(pts);
        }
    }
    return s;
}

/// Largest distance of any vertex of strand i from the circle of radius r about the z axis.
double radialError(const StrandSet& s, std::size_t i, double r)
{
    double worst = 0.0;
    for (std::size_t v = s.begin(i); v < s.end(i); ++v) {
        const Vec3f p = s.positions[v];
        worst = std::max(worst, std::abs(std::hypot(double(p.x()), double(p.y())) - r));
    }
    return worst;
}

} // namespace

TEST_CASE("retraceStrands: a uniform field retraces straight strands exactly", "[field]")
{
    StrandSet s;
    const Vec3f dir = Vec3f(0.3f, -1.f, 0.2f).unitSafe();
    for (int i = 0; i < 6; ++i) {
        std::vector<Vec3f> pts;
        const Vec3f root(0.37f * float(i), 0.11f, -0.23f * float(i));
        for (int k = 0; k < 17; ++k) pts.push_back(root + dir * (0.6f * float(k)));
        s.addStrand(pts);
    }
    FieldParams p;
    p.voxelSize = 0.4;
    const TangentField f = estimateTangentField(s, p);
    for (Integrator integ : {Integrator::Euler, Integrator::RK2, Integrator::RK3, Integrator::RK4}) {
        TraceParams tp;
        tp.integrator = integ;
        TraceStats stats;
        const StrandSet r = retraceStrands(s, *f.tangent, tp, &stats);
        CAPTURE(integratorName(integ));
        REQUIRE(stats.fullLength == s.numStrands());
        test::requireSameStrands(s, r, 2e-5f);
        REQUIRE(meanVertexDisplacement(s, r) < 1e-5);
        REQUIRE(meanTangentAngleDeg(r, *f.tangent) < 1e-2);
    }
}

TEST_CASE("retraceStrands: concentric circles stay on their circles, RK4 closer than Euler, error falling with the step", "[field]")
{
    const StrandSet circles = concentricCircles(3.0, 0.25, 13, 3, 1.5 * M_PI);
    FieldParams p;
    p.voxelSize = 0.2;
    const TangentField f = estimateTangentField(circles, p);
    auto worst = [&](Integrator integ, double step) {
        TraceParams tp;
        tp.integrator = integ;
        tp.step = step;
        TraceStats stats;
        const StrandSet r = retraceStrands(circles, *f.tangent, tp, &stats);
        // Euler's outward drift (below) takes the outermost ring of each layer out of the hair
        // volume; every other strand stays in it for its whole length.
        REQUIRE(stats.fullLength >= circles.numStrands() - (integ == Integrator::Euler ? 3 : 0));
        double e = 0.0;
        // The middle layer, away from the hair volume's top and bottom faces.
        for (std::size_t i = 13; i < 25; ++i) e = std::max(e, radialError(r, i, 3.0 + 0.25 * double(i - 13)));
        return e;
    };
    const double euler1 = worst(Integrator::Euler, 0.2), euler2 = worst(Integrator::Euler, 0.1), euler3 = worst(Integrator::Euler, 0.05);
    const double rk4 = worst(Integrator::RK4, 0.1);
    CAPTURE(euler1, euler2, euler3, rk4);
    // Forward Euler on a circle spirals out: each step of length h adds h²/2r to the radius, so
    // after an arc of angle theta the radius has grown by theta·h/2, whatever the radius. Stated
    // tolerance: within 10% of that plus 0.01 for the field's discretization, and first order
    // (halving the step halves the error). RK4 stays within 0.5% of the smallest radius.
    const double theta = 1.5 * M_PI;
    REQUIRE(euler1 < 1.1 * theta * 0.2 / 2 + 0.01);
    REQUIRE(euler2 < 1.1 * theta * 0.1 / 2 + 0.01);
    REQUIRE(euler3 < 1.1 * theta * 0.05 / 2 + 0.01);
    REQUIRE(euler1 / euler2 == Approx(2.0).epsilon(0.1));
    REQUIRE(euler2 / euler3 == Approx(2.0).epsilon(0.1));
    REQUIRE(rk4 < 0.005 * 3.0);
    REQUIRE(rk4 < euler3 / 10);
}

TEST_CASE("retraceStrands: every stop reason is counted", "[field]")
{
    // A field made of one short strand along x.
    StrandSet shortOne;
    shortOne.addStrand(std::vector<Vec3f>{Vec3f(0.f), Vec3f(2.f, 0.f, 0.f)});
    FieldParams p;
    p.voxelSize = 0.5;
    const TangentField f = estimateTangentField(shortOne, p);
    StrandSet longOne;
    longOne.addStrand(std::vector<Vec3f>{Vec3f(0.f), Vec3f(5.f, 0.f, 0.f), Vec3f(10.f, 0.f, 0.f)});

    TraceParams tp;
    tp.margin = 0;
    TraceStats stats;
    std::vector<StopReason> reasons;
    StrandSet r = retraceStrands(longOne, *f.tangent, tp, &stats, &reasons);
    REQUIRE(stats.leftField == 1);
    REQUIRE(reasons[0] == StopReason::LeftField);
    // It keeps what it traced: the root, then the point where it stopped, past the field's end.
    REQUIRE(r.size(0) == 2);
    REQUIRE(r.tip(0).x() == Approx(2.5).margin(0.25));

    tp.margin = 2;  // it continues straight for two more voxels
    r = retraceStrands(longOne, *f.tangent, tp, &stats);
    REQUIRE(stats.leftField == 1);
    REQUIRE(r.tip(0).x() == Approx(3.5).margin(0.25));

    tp.maxSteps = 3;
    r = retraceStrands(longOne, *f.tangent, tp, &stats, &reasons);
    REQUIRE(stats.maxSteps == 1);
    REQUIRE(r.tip(0).x() == Approx(0.75));

    // Opposing strands cancel: the field vanishes there.
    StrandSet opposing;
    opposing.addStrand(std::vector<Vec3f>{Vec3f(-3.f, 0.f, 0.f), Vec3f(3.f, 0.f, 0.f)});
    opposing.addStrand(std::vector<Vec3f>{Vec3f(3.f, 0.f, 0.f), Vec3f(-3.f, 0.f, 0.f)});
    const TangentField g = estimateTangentField(opposing, p);
    r = retraceStrands(opposing, *g.tangent, TraceParams{}, &stats);
    REQUIRE(stats.vanished == 2);
    REQUIRE(stats.fullLength == 0);
    REQUIRE(r.numStrands() == 2);
    REQUIRE(r.size(0) == 2);  // at least the root twice
}

TEST_CASE("retraceStrands: input vertex counts, or every step", "[field]")
{
    const StrandSet circles = concentricCircles(3.0, 0.5, 3, 2, 1.0);
    FieldParams p;
    p.voxelSize = 0.25;
    const TangentField f = estimateTangentField(circles, p);
    TraceParams tp;
    TraceStats stats;
    StrandSet r = retraceStrands(circles, *f.tangent, tp, &stats);
    REQUIRE(r.offsets == circles.offsets);
    tp.vertices = RetraceVertices::Steps;
    tp.step = 0.1;
    r = retraceStrands(circles, *f.tangent, tp, &stats);
    REQUIRE(r.numVertices() == stats.steps + r.numStrands());
    const std::vector<float> lin = strandLengths(circles), lout = strandLengths(r);
    for (std::size_t i = 0; i < lin.size(); ++i) REQUIRE(lout[i] == Approx(lin[i]).epsilon(1e-4));
}

TEST_CASE("retraceStrands: bitwise identical with 1 and 2 threads", "[field]")
{
    const StrandSet circles = concentricCircles(2.0, 0.3, 10, 4, 4.0);
    FieldParams p;
    p.voxelSize = 0.3;
    const TangentField f = estimateTangentField(circles, p);
    StrandSet one, two;
    {
        tbb::global_control c(tbb::global_control::max_allowed_parallelism, 1);
        one = retraceStrands(circles, *f.tangent, TraceParams{});
    }
    {
        tbb::global_control c(tbb::global_control::max_allowed_parallelism, 2);
        two = retraceStrands(circles, *f.tangent, TraceParams{});
    }
    REQUIRE(one.offsets == two.offsets);
    REQUIRE(std::memcmp(one.positions.data(), two.positions.data(), one.positions.size() * sizeof(Vec3f)) == 0);
}

TEST_CASE("retraceStrands: strands stopping early all through the set keep their own prefixes", "[field]")
{
    // A field of straight strands along +x over x in [0, 10], on a 30 x 20 lattice in (y, z).
    StrandSet fieldStrands;
    for (int a = 0; a < 30; ++a) {
        for (int b = 0; b < 20; ++b) {
            fieldStrands.addStrand(std::vector<Vec3f>{Vec3f(0.f, 0.3f * a, 0.3f * b), Vec3f(10.f, 0.3f * a, 0.3f * b)});
        }
    }
    FieldParams p;
    p.voxelSize = 0.5;
    const TangentField f = estimateTangentField(fieldStrands, p);
    // Probes from x = 0: every third one is longer than the field and stops where it leaves it,
    // so the kept prefixes shift every later strand, in both halves of the set (which a retrace
    // on two threads compacts separately). Vertex counts vary so that the shifts do too.
    StrandSet probes;
    for (int k = 0; k < 3000; ++k) {
        const int lattice = k % 600;
        const float y = 0.3f * float(lattice / 20), z = 0.3f * float(lattice % 20);
        const float length = k % 3 == 0 ? 14.f : 8.f;
        const int n = 5 + (k * 7) % 31;
        std::vector<Vec3f> pts;
        for (int i = 0; i < n; ++i) pts.emplace_back(length * float(i) / float(n - 1), y, z);
        probes.addStrand(pts);
    }
    TraceParams tp;
    tp.margin = 0;
    StrandSet one, two;
    TraceStats stats;
    {
        tbb::global_control c(tbb::global_control::max_allowed_parallelism, 1);
        one = retraceStrands(probes, *f.tangent, tp, &stats);
    }
    REQUIRE(stats.leftField == 1000);
    REQUIRE(stats.fullLength == 2000);
    {
        tbb::global_control c(tbb::global_control::max_allowed_parallelism, 2);
        two = retraceStrands(probes, *f.tangent, tp);
    }
    REQUIRE(one.offsets == two.offsets);
    REQUIRE(one.positions == two.positions);
    // Each strand is what a retrace of it alone gives (no compaction there).
    for (std::size_t k = 0; k < probes.numStrands(); k += 7) {
        CAPTURE(k);
        StrandSet alone;
        alone.addStrand(probes.data(k), probes.size(k));
        const StrandSet r = retraceStrands(alone, *f.tangent, tp);
        REQUIRE(two.size(k) == r.size(0));
        REQUIRE(std::equal(r.positions.begin(), r.positions.end(), two.positions.begin() + std::ptrdiff_t(two.begin(k))));
        if (k % 3 == 0) {
            REQUIRE(r.size(0) < probes.size(k));
            REQUIRE(r.tip(0).x() == Approx(10.25).margin(0.3));  // where the field ends
        } else {
            REQUIRE(r.size(0) == probes.size(k));
            REQUIRE(r.tip(0).x() == Approx(8.0).margin(1e-4));
        }
    }
}

TEST_CASE("retraceStrandsInto: the same strands as retraceStrands, in the output's own storage", "[field]")
{
    const StrandSet circles = concentricCircles(2.0, 0.3, 10, 4, 4.0);
    FieldParams p;
    p.voxelSize = 0.3;
    const TangentField f = estimateTangentField(circles, p);
    const StrandSet expected = retraceStrands(circles, *f.tangent, TraceParams{});
    StrandSet out;
    out.addStrand(std::vector<Vec3f>{Vec3f(1.f), Vec3f(2.f)});  // replaced, whatever it held
    out.thickness = {0.5f, 0.5f};
    retraceStrandsInto(circles, *f.tangent, TraceParams{}, out);
    REQUIRE(out.offsets == expected.offsets);
    REQUIRE(out.positions == expected.positions);
    REQUIRE(out.thickness.empty());
    // Again into the same set: its storage is reused, not reallocated.
    const Vec3f* storage = out.positions.data();
    retraceStrandsInto(circles, *f.tangent, TraceParams{}, out);
    REQUIRE(out.positions.data() == storage);
    REQUIRE(out.positions == expected.positions);
    // Never into the input itself.
    StrandSet same = circles;
    REQUIRE_THROWS_WITH(retraceStrandsInto(same, *f.tangent, TraceParams{}, same), Contains("must be another StrandSet"));
}

TEST_CASE("retraceStrands: bad parameters and grids", "[field]")
{
    const StrandSet circles = concentricCircles(2.0, 0.3, 2, 1, 1.0);
    FieldParams p;
    p.voxelSize = 0.3;
    const TangentField f = estimateTangentField(circles, p);
    TraceParams tp;
    tp.step = -1.0;
    REQUIRE_THROWS_AS(retraceStrands(circles, *f.tangent, tp), ValueError);
    tp.step = 0.0;
    tp.vanishThreshold = 1.5;
    REQUIRE_THROWS_AS(retraceStrands(circles, *f.tangent, tp), ValueError);
    REQUIRE_THROWS_WITH(retraceStrands(circles, *f.density, TraceParams{}), Contains("holds float values; tracing needs a vector grid"));
}


TEST_CASE("meanTangentAnglesDeg: strands at a known angle to a uniform field, both sets as each on its own", "[field]")
{
    // A uniform field along x (estimated from straight strands along x), then strands across it.
    StrandSet along, tilted, outside;
    const double angleDeg = 30.0;
    const Vec3f tilt(float(std::cos(angleDeg * M_PI / 180.0)), float(std::sin(angleDeg * M_PI / 180.0)), 0.f);
    for (int i = 0; i < 40; ++i) {
        std::vector<Vec3f> a, t, o;
        const Vec3f root(0.f, 0.2f * float(i % 8), 0.2f * float(i / 8));
        for (int k = 0; k < 40; ++k) a.push_back(root + Vec3f(0.25f * float(k), 0.f, 0.f));
        for (int k = 0; k < 6; ++k) t.push_back(root + Vec3f(2.f, 0.2f, 0.2f) + tilt * (0.1f * float(k)));
        for (int k = 0; k < 6; ++k) o.push_back(root + Vec3f(100.f + float(k), 0.f, 0.f));  // far outside the field
        along.addStrand(a);
        tilted.addStrand(t);
        outside.addStrand(o);
    }
    FieldParams p;
    p.voxelSize = 0.5;
    const TangentField f = estimateTangentField(along, p);
    std::size_t n = 0;
    REQUIRE(meanTangentAngleDeg(tilted, *f.tangent, &n) == Approx(angleDeg).margin(1e-3));
    REQUIRE(n == tilted.numVertices());
    const TangentAngles both = meanTangentAnglesDeg(tilted, along, *f.tangent);
    std::size_t nAlong = 0;
    REQUIRE(both.beforeDeg == meanTangentAngleDeg(tilted, *f.tangent));
    REQUIRE(both.afterDeg == meanTangentAngleDeg(along, *f.tangent, &nAlong));
    REQUIRE(both.afterDeg < 1e-2);
    REQUIRE(both.countedBefore == n);
    REQUIRE(both.countedAfter == nAlong);
    // Outside the field nothing is counted; the threaded and serial passes agree exactly.
    const TangentAngles none = meanTangentAnglesDeg(outside, tilted, *f.tangent, false);
    REQUIRE(none.countedBefore == 0);
    REQUIRE(none.beforeDeg == 0.0);
    REQUIRE(none.afterDeg == meanTangentAnglesDeg(outside, tilted, *f.tangent, true).afterDeg);
}

namespace {

/// A smooth swirling field over the voxels [-R, R]³ of a grid of voxel size @a h whose origin
/// lies at @a offset: a drift plus a rotation about a random axis (so streamlines curve, and
/// leave the box).
openvdb::Vec3SGrid::Ptr swirlField(Rng& rng, double h, const Vec3d& offset, int R)
{
    auto grid = openvdb::Vec3SGrid::create(openvdb::Vec3f(0.f));
    openvdb::math::Transform::Ptr xf = openvdb::math::Transform::createLinearTransform(h);
    xf->postTranslate(offset);
    grid->setTransform(xf);
    grid->setName("tangent");
    const Vec3d drift = Vec3d(rng.uniform() - 0.5, rng.uniform() - 0.5, rng.uniform() - 0.5) * 2.0;
    const Vec3d axis = Vec3d(rng.uniform() - 0.5, rng.uniform() - 0.5, rng.uniform() - 0.5) * (1.5 / R);
    auto acc = grid->getAccessor();
    for (int x = -R; x <= R; ++x) {
        for (int y = -R; y <= R; ++y) {
            for (int z = -R; z <= R; ++z) {
                const Vec3d v = drift + axis.cross(Vec3d(x, y, z));
                acc.setValue(openvdb::Coord(x, y, z), openvdb::Vec3f(float(v.x()), float(v.y()), float(v.z())));
            }
        }
    }
    return grid;
}

/// Straight input strands (only their roots and arc lengths matter) rooted inside the box of
/// swirlField(), some long enough to leave it.
StrandSet randomRoots(Rng& rng, double h, const Vec3d& offset, int R, std::size_t count)
{
    StrandSet s;
    for (std::size_t i = 0; i < count; ++i) {
        const Vec3d root = offset + Vec3d(rng.uniform() - 0.5, rng.uniform() - 0.5, rng.uniform() - 0.5) * (1.6 * R * h);
        const Vec3d dir = Vec3d(rng.uniform() - 0.5, rng.uniform() - 0.5, rng.uniform() - 0.5).unitSafe();
        const double length = (0.2 + 2.0 * rng.uniform()) * R * h;
        const std::size_t n = 2 + std::size_t(rng.uniform() * 40.0);
        std::vector<Vec3f> pts;
        for (std::size_t k = 0; k < n; ++k) {
            const Vec3d p = root + dir * (length * double(k) / double(n - 1));
            pts.emplace_back(float(p.x()), float(p.y()), float(p.z()));
        }
        s.addStrand(pts);
    }
    return s;
}

} // namespace

TEST_CASE("retraceStrands: the lane kernel holds to the general engine, its two clones bitwise to each other", "[field]")
{
    // Seeded cases across voxel sizes, grid offsets, integrators, margins and vertex modes.
    for (std::uint64_t seed = 0; seed < 24; ++seed) {
        Rng rng(2024, seed);
        const double h = std::pow(10.0, -2.0 + 3.0 * rng.uniform());  // 0.01 .. 10
        const Vec3d offset = Vec3d(rng.uniform() - 0.5, rng.uniform() - 0.5, rng.uniform() - 0.5) * (20.0 * h);
        const int R = 6 + int(rng.uniform() * 10.0);
        const openvdb::Vec3SGrid::Ptr field = swirlField(rng, h, offset, R);
        const StrandSet in = randomRoots(rng, h, offset, R, 60);
        TraceParams tp;
        tp.integrator = seed % 5 == 4 ? Integrator::RK3 : seed % 4 == 3 ? Integrator::RK4 : seed % 4 == 2 ? Integrator::RK2 : Integrator::Euler;
        tp.margin = int(seed % 3);
        tp.vertices = seed % 5 == 4 ? RetraceVertices::Steps : RetraceVertices::Input;
        tp.step = seed % 2 ? 0.0 : (0.2 + 0.6 * rng.uniform()) * h;
        CAPTURE(seed, h, R, integratorName(tp.integrator), tp.margin, tp.step);

        tp.kernel = TraceKernel::Scalar;
        TraceStats scalarStats;
        std::vector<StopReason> scalarReasons;
        const StrandSet scalar = retraceStrands(in, *field, tp, &scalarStats, &scalarReasons);
        tp.kernel = TraceKernel::Auto;
        TraceStats laneStats;
        std::vector<StopReason> laneReasons;
        const StrandSet lanes = retraceStrands(in, *field, tp, &laneStats, &laneReasons);

        REQUIRE(laneReasons == scalarReasons);
        REQUIRE(laneStats.steps == scalarStats.steps);
        REQUIRE(lanes.offsets == scalar.offsets);
        // Beyond the rounding of the output floats themselves (a float world coordinate far from
        // the origin in voxels resolves less than 1e-6 voxel): within 1e-6 voxel where the lanes
        // step through the engine (RK2, RK4), within 1e-5 voxel for their own Euler steps, whose
        // positions are float offsets within a brick (2^-21 voxel apart: over a strand's steps
        // the rounding adds up to a few 1e-6 voxel; 3.1e-6 at most over these cases).
        double worst = 0.0;
        for (std::size_t v = 0; v < scalar.numVertices(); ++v) {
            const Vec3f& a = lanes.positions[v];
            const Vec3f& b = scalar.positions[v];
            for (int c = 0; c < 3; ++c) {
                const double ulp = double(std::nextafter(std::abs(b[c]), INFINITY) - std::abs(b[c]));
                worst = std::max(worst, (std::abs(double(a[c]) - double(b[c])) - 2.0 * ulp) / h);
            }
        }
        CAPTURE(worst);
        REQUIRE(worst <= (tp.integrator == Integrator::Euler ? 1e-5 : 1e-6));

        // The baseline and AVX2 clones of the lane loop: bitwise the same.
        tp.kernel = TraceKernel::LanesSse;
        const StrandSet sse = retraceStrands(in, *field, tp);
        REQUIRE(sse.offsets == lanes.offsets);
        REQUIRE(std::memcmp(sse.positions.data(), lanes.positions.data(), sse.positions.size() * sizeof(Vec3f)) == 0);
        if (__builtin_cpu_supports("avx2")) {
            tp.kernel = TraceKernel::LanesAvx2;
            const StrandSet avx = retraceStrands(in, *field, tp);
            REQUIRE(avx.offsets == lanes.offsets);
            REQUIRE(std::memcmp(avx.positions.data(), lanes.positions.data(), avx.positions.size() * sizeof(Vec3f)) == 0);
        }
    }
}

TEST_CASE("retraceStrands: the scalar kernel is bitwise identical with 1 and 2 threads", "[field]")
{
    Rng rng(7);
    const openvdb::Vec3SGrid::Ptr field = swirlField(rng, 0.3, Vec3d(0.1, -0.2, 0.05), 10);
    const StrandSet in = randomRoots(rng, 0.3, Vec3d(0.1, -0.2, 0.05), 10, 300);
    TraceParams tp;
    tp.kernel = TraceKernel::Scalar;
    StrandSet one, two;
    {
        tbb::global_control c(tbb::global_control::max_allowed_parallelism, 1);
        one = retraceStrands(in, *field, tp);
    }
    {
        tbb::global_control c(tbb::global_control::max_allowed_parallelism, 2);
        two = retraceStrands(in, *field, tp);
    }
    REQUIRE(one.numStrands() == in.numStrands());
    REQUIRE(one.offsets == two.offsets);
    REQUIRE(std::memcmp(one.positions.data(), two.positions.data(), one.positions.size() * sizeof(Vec3f)) == 0);
}

TEST_CASE("resolveStepLength: the default step is half a voxel; a negative step is an error naming it", "[field]")
{
    REQUIRE(kDefaultStepVoxels == 0.5);
    REQUIRE(resolveStepLength(0.0, 0.4, "here") == Approx(0.2).margin(1e-15));
    REQUIRE(resolveStepLength(0.03, 0.4, "here") == 0.03);
    REQUIRE_THROWS_WITH(resolveStepLength(-0.1, 0.4, "here"), Contains("here: step -0.1") && Contains("must be 0 (half a voxel) or a positive finite length"));
    REQUIRE_THROWS_AS(resolveStepLength(std::nan(""), 0.4, "here"), ValueError);
    TraceParams tp;
    tp.margin = TraceParams::kMaxMargin + 1;
    REQUIRE_THROWS_WITH(tp.validate("retraceStrands"), Contains("retraceStrands: margin 17 voxels must be between 0 and 16"));
}

TEST_CASE("FieldSampler::sampleScalar: a float grid beside the vector bricks, bit for bit the lane of a vector brick holding it", "[field]")
{
    // A sparse vector grid (scattered leaves and voxels, so that many cells fall back to the
    // tree) and a float grid of another topology. The reference is the scalar carried in the x
    // lane of a vector grid of the vector grid's topology, sampled by sample(): the spread's old
    // route in the consistent retrace.
    std::mt19937 rng(7);
    std::uniform_int_distribution<int> coord(-20, 27);
    std::uniform_real_distribution<float> value(-1.f, 1.f);
    openvdb::Vec3STree vectors(openvdb::Vec3f(0.f));
    openvdb::FloatTree scalars(0.f);
    for (int i = 0; i < 12000; ++i) {
        const openvdb::Coord c(coord(rng), coord(rng), coord(rng));
        if (i % 3 != 2) vectors.setValueOn(c, openvdb::Vec3f(value(rng), value(rng), value(rng)));
        if (i % 3 != 1) scalars.setValueOn(c, value(rng));
    }
    scalars.setValueOff(openvdb::Coord(0, 0, 0), 0.5f);  // an inactive value where the vectors may be on
    openvdb::Vec3STree lane(openvdb::Vec3f(0.f));
    lane.topologyUnion(vectors);
    {
        openvdb::tree::ValueAccessor<const openvdb::FloatTree> acc(scalars);
        for (auto leaf = lane.beginLeaf(); leaf; ++leaf) {
            for (auto it = leaf->beginValueOn(); it; ++it) it.setValue(openvdb::Vec3f(acc.getValue(it.getCoord()), 0.f, 0.f));
        }
    }
    const BrickedField<openvdb::Vec3STree> withScalar(vectors, &scalars), reference(lane);
    FieldSampler<openvdb::Vec3STree> s(withScalar), r(reference);
    std::uniform_real_distribution<double> pos(-24.0, 31.0);
    std::size_t nonzero = 0;
    for (int i = 0; i < 20000; ++i) {
        const openvdb::Vec3d p(pos(rng), pos(rng), pos(rng));
        // Interleaved with vector samples elsewhere, so that the sampler's cached cell moves.
        if (i % 2) s.sample(openvdb::Vec3d(pos(rng), pos(rng), pos(rng)));
        const float got = s.sampleScalar(p), want = r.sample(p)[0];
        CAPTURE(p, got, want);
        REQUIRE(std::memcmp(&got, &want, sizeof got) == 0);
        // The vector lanes are those of the grid without a scalar.
        const Float4 v = s.sample(p), w = r.sample(p);
        REQUIRE(v[3] == w[3]);
        nonzero += got != 0.f ? 1 : 0;
    }
    CAPTURE(nonzero);
    REQUIRE(nonzero > 2000);  // a tenth of the points meet the scalar (17 % with this seed)
}
