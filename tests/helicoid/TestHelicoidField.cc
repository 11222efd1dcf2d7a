#include "../TestUtil.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/field/TangentField.h>
#include <vdbhair/helicoid/HelicoidField.h>
#include <vdbhair/io/VdbFile.h>
#include <vdbhair/strands/Measures.h>

using namespace vdbhair;
using Catch::Matchers::Contains;

namespace {
/// The exact tangent field of concentric circles about the z axis, in an annulus about radius 7.5.
openvdb::Vec3SGrid::Ptr circleField(double h)
{
    auto g = openvdb::Vec3SGrid::create(openvdb::Vec3f(0.f));
    g->setTransform(openvdb::math::Transform::createLinearTransform(h));
    auto acc = g->getAccessor();
    const int n = int(12.0 / h) + 1;
    for (int i = -n; i <= n; ++i) {
        for (int j = -n; j <= n; ++j) {
            for (int k = -2; k <= 2; ++k) {
                const double x = i * h, y = j * h, r = std::hypot(x, y);
                if (r < 7.5 - 2.0 * h || r > 7.5 + 2.0 * h) continue;
                acc.setValue(openvdb::Coord(i, j, k), openvdb::Vec3f(float(-y / r), float(x / r), 0.f));
            }
        }
    }
    g->setName("tangent");
    return g;
}
} // namespace

TEST_CASE("estimateHelicoidField: concentric circles give kT = 1/r, N towards the centre", "[helicoid]")
{
    initializeOpenVdb();
    const double h = 0.5;
    const auto g = circleField(h);
    const HelicoidFieldGrids f = estimateHelicoidField(*g);
    REQUIRE(f.k->activeVoxelCount() == g->activeVoxelCount());
    REQUIRE(f.k->getName() == "helicoid_k");
    REQUIRE(f.alpha->getName() == "helicoid_alpha");
    REQUIRE(f.frameT->getVectorType() == openvdb::VEC_CONTRAVARIANT_RELATIVE);
    REQUIRE(f.k->getVectorType() == openvdb::VEC_INVARIANT);
    auto ka = f.k->getConstAccessor();
    auto na = f.frameN->getConstAccessor();
    for (const openvdb::Coord c : {openvdb::Coord(15, 0, 0), openvdb::Coord(0, -15, 1), openvdb::Coord(11, 11, -1)}) {
        const double r = c.asVec3d().length() > 0 ? std::hypot(c.x() * h, c.y() * h) : 0.0;
        const openvdb::Vec3f k = ka.getValue(c), n = na.getValue(c);
        CAPTURE(c, r, k, n);
        REQUIRE(k.x() == Approx(1.0 / r).epsilon(0.03));
        REQUIRE(std::abs(k.y()) < 0.01);
        REQUIRE(std::abs(k.z()) < 0.01);
        REQUIRE(n.x() * c.x() + n.y() * c.y() < 0.f);  // towards the centre
    }
}

TEST_CASE("retraceHelicoidField: a circle through the helicoid field of concentric circles", "[helicoid]")
{
    initializeOpenVdb();
    StrandSet s;
    std::vector<Vec3f> pts;
    for (int a = 0; a <= 100; ++a) pts.emplace_back(float(7.5 * std::cos(a * 0.05)), float(7.5 * std::sin(a * 0.05)), 0.1f);
    s.addStrand(pts);
    for (double h : {0.5, 2.0}) {
        const auto g = circleField(h);
        const HelicoidFieldGrids f = estimateHelicoidField(*g);
        TraceParams tp;
        tp.integrator = Integrator::RK4;
        tp.step = 0.1;
        TraceStats stats;
        const StrandSet r = retraceHelicoidField(s, f, tp, &stats);
        REQUIRE(stats.fullLength == 1);
        REQUIRE(r.offsets == s.offsets);
        double worst = 0.0;
        for (const Vec3f& p : r.positions) worst = std::max(worst, std::abs(std::hypot(double(p.x()), double(p.y())) - 7.5));
        CAPTURE(h, worst);
        REQUIRE(worst < (h < 1.0 ? 1e-3 : 1e-2));
    }
}

TEST_CASE("estimateHelicoidField / readHelicoidField: from strands, through a file", "[helicoid]")
{
    initializeOpenVdb();
    StrandSet s;
    for (int k = 0; k < 6; ++k) {
        std::vector<Vec3f> pts;
        for (int a = 0; a <= 60; ++a) pts.emplace_back(float((5.0 + 0.3 * k) * std::cos(a * 0.05)), float((5.0 + 0.3 * k) * std::sin(a * 0.05)), 0.f);
        s.addStrand(pts);
    }
    FieldParams p;
    p.voxelSize = 0.5;
    const TangentField t = estimateTangentField(s, p);
    const HelicoidFieldGrids f = estimateHelicoidField(*t.tangent);
    const std::string path = test::tempPath("helicoid.vdb");
    writeVdbGrids(path, {t.tangent, f.k, f.alpha, f.frameT, f.frameN}, "test");
    const HelicoidFieldGrids r = readHelicoidField(path);
    REQUIRE(r.k->activeVoxelCount() == f.k->activeVoxelCount());
    REQUIRE(r.k->metaValue<double>("vdbhair_voxel_size") == 0.5);
    // Every value of every grid, voxel by voxel, as written (float grids: stored exactly).
    auto sameValues = [](const auto& written, const auto& read) {
        REQUIRE(read.activeVoxelCount() == written.activeVoxelCount());
        REQUIRE(written.activeVoxelCount() > 0);
        auto acc = read.getConstAccessor();
        std::size_t differ = 0;
        for (auto it = written.cbeginValueOn(); it; ++it) differ += !(acc.isValueOn(it.getCoord()) && acc.getValue(it.getCoord()) == *it);
        REQUIRE(differ == 0);
    };
    sameValues(*f.k, *r.k);
    sameValues(*f.alpha, *r.alpha);
    sameValues(*f.frameT, *r.frameT);
    sameValues(*f.frameN, *r.frameN);
    const std::string plain = test::tempPath("plain.vdb");
    writeVdbGrids(plain, {t.tangent}, "test");
    REQUIRE_THROWS_WITH(readHelicoidField(plain), Contains("no grid named 'helicoid_k'") && Contains("estimateHelicoidField"));
}

TEST_CASE("retraceHelicoidField: the engine's rules: a negative step is an error naming it, every step on request, attributes kept", "[helicoid]")
{
    initializeOpenVdb();
    StrandSet s;
    std::vector<Vec3f> pts;
    for (int a = 0; a <= 40; ++a) pts.emplace_back(float(7.5 * std::cos(a * 0.05)), float(7.5 * std::sin(a * 0.05)), 0.1f);
    s.addStrand(pts);
    s.strandId = {42};
    s.thickness.assign(pts.size(), 0.25f);
    const auto g = circleField(0.5);
    const HelicoidFieldGrids f = estimateHelicoidField(*g);
    TraceParams tp;
    tp.step = -0.1;
    REQUIRE_THROWS_WITH(retraceHelicoidField(s, f, tp), Contains("retraceHelicoidField: step -0.1") && Contains("must be 0 (half a voxel)"));
    tp.step = 0.0;
    tp.margin = -1;
    REQUIRE_THROWS_WITH(retraceHelicoidField(s, f, tp), Contains("retraceHelicoidField: margin -1"));
    tp.margin = 3;

    // The default step is half a voxel: the strand's length (2 · 7.5 · sin(1) as a chord sum,
    // about 7.5 · 2) over 0.25 steps.
    tp.vertices = RetraceVertices::Steps;
    TraceStats stats;
    const StrandSet steps = retraceHelicoidField(s, f, tp, &stats);
    std::vector<double> arc(pts.size());
    arcLengths(pts.data(), pts.size(), arc.data());
    REQUIRE(stats.fullLength == 1);
    REQUIRE(stats.steps == stepCount(arc.back(), 0.25));
    REQUIRE(steps.numVertices() == stats.steps + 1);
    REQUIRE(steps.strandId == s.strandId);
    REQUIRE(steps.thickness.empty());  // per-vertex attributes only where the input's vertices are kept

    tp.vertices = RetraceVertices::Input;
    const StrandSet kept = retraceHelicoidField(s, f, tp, &stats);
    REQUIRE(kept.offsets == s.offsets);
    REQUIRE(kept.strandId == s.strandId);
    REQUIRE(kept.thickness == s.thickness);
    // Its vertices lie on the steps' polyline: the tip is the last step point exactly.
    REQUIRE(kept.positions.back() == steps.positions.back());
}

namespace {
/// Sixteen strands on the same helix (radius r, pitch 2πc: z = c a) with phases 2πi/16: the
/// curvature everywhere on the cylinder is r / (r² + c²), the curvature vector points at the axis.
StrandSet phasedHelices(double r, double c)
{
    StrandSet s;
    for (int i = 0; i < 16; ++i) {
        const double phase = 2.0 * M_PI * i / 16.0;
        std::vector<Vec3f> pts;
        for (int j = 0; j <= 120; ++j) {
            const double a = 0.1 * j;
            pts.emplace_back(float(r * std::cos(a + phase)), float(r * std::sin(a + phase)), float(c * a));
        }
        s.addStrand(pts);
    }
    return s;
}
} // namespace

TEST_CASE("estimateHelicoidField(strands): helices with different phases give the helix curvature, N towards the axis", "[helicoid]")
{
    initializeOpenVdb();
    const double r = 5.0, c = 2.0, curvature = r / (r * r + c * c);
    const StrandSet s = phasedHelices(r, c);
    for (double h : {0.5, 1.0}) {
        FieldParams p;
        p.voxelSize = h;
        const TangentField t = estimateTangentField(s, p);
        const HelicoidFieldGrids f = estimateHelicoidField(s, *t.tangent);
        const HelicoidFieldGrids serial = estimateHelicoidField(s, *t.tangent, false);
        REQUIRE(f.k->activeVoxelCount() == t.tangent->activeVoxelCount());
        REQUIRE(f.k->metaValue<std::string>("vdbhair_helicoid_fit").find("strand pieces") != std::string::npos);
        // Voxels whose centre lies on the cylinder, away from the strands' ends.
        auto ka = f.k->getConstAccessor();
        auto na = f.frameN->getConstAccessor();
        auto ks = serial.k->getConstAccessor();
        std::size_t checked = 0, differ = 0;
        std::vector<double> kT;
        for (auto it = t.tangent->cbeginValueOn(); it; ++it) {
            const Vec3d x = t.tangent->transform().indexToWorld(it.getCoord());
            differ += !(ks.getValue(it.getCoord()) == ka.getValue(it.getCoord()));
            if (std::abs(std::hypot(x.x(), x.y()) - r) > 0.1 * h || x.z() < 3.0 || x.z() > 20.0) continue;
            const openvdb::Vec3f k = ka.getValue(it.getCoord()), n = na.getValue(it.getCoord());
            const Vec3d inward = Vec3d(-x.x(), -x.y(), 0.0).unit();
            CAPTURE(h, x, k, n, curvature);
            REQUIRE(Vec3d(n).dot(inward) > 0.95);
            kT.push_back(k.x());
            ++checked;
        }
        REQUIRE(differ == 0);  // independent of the thread count
        REQUIRE(checked >= 10);
        std::sort(kT.begin(), kT.end());
        CAPTURE(h, checked, kT.front(), kT[kT.size() / 2], kT.back());
        REQUIRE(kT[kT.size() / 2] == Approx(curvature).epsilon(0.05));
        REQUIRE(kT.front() > 0.8 * curvature);
        REQUIRE(kT.back() < 1.2 * curvature);
    }
}

TEST_CASE("retraceHelicoidField: curls of unlike phases that share voxels retrace closer than through the tangent field", "[helicoid]")
{
    // 25 helices of radius 1 and pitch 2 pi * 0.6 along z, axes 2 apart on a 5 x 5 grid, each at its
    // own phase, traced at a voxel of 0.8: each voxel near a curl holds pieces of 1-3 curls in
    // different phases. Both fields are retraced with the same integrator.
    initializeOpenVdb();
    const double r = 1.0, c = 0.6;
    StrandSet s;
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(0.0, 2.0 * M_PI);
    for (int i = 0; i < 25; ++i) {
        const double cx = 2.0 * (i % 5), cy = 2.0 * (i / 5), phase = u(rng);
        std::vector<Vec3f> pts;
        for (int j = 0; j <= 400; ++j) {
            const double a = 0.05 * j;
            pts.emplace_back(float(cx + r * std::cos(a + phase)), float(cy + r * std::sin(a + phase)), float(c * a));
        }
        s.addStrand(pts);
    }
    double length = 0.0;
    for (std::size_t i = 0; i < s.numStrands(); ++i) length += polylineLength(s.data(i), s.size(i));
    length /= double(s.numStrands());
    FieldParams p;
    p.voxelSize = 0.8;
    const TangentField t = estimateTangentField(s, p);
    const HelicoidFieldGrids f = estimateHelicoidField(s, *t.tangent);
    TraceParams tp;
    tp.integrator = kHelicoidRetraceIntegrator;
    const double eT = meanVertexDisplacement(s, retraceStrands(s, *t.tangent, tp)) / length;
    const double eH = meanVertexDisplacement(s, retraceHelicoidField(s, f, tp)) / length;
    tp.integrator = Integrator::Euler;
    const double eTe = meanVertexDisplacement(s, retraceStrands(s, *t.tangent, tp)) / length;
    const double eHe = meanVertexDisplacement(s, retraceHelicoidField(s, f, tp)) / length;
    std::cout << "25 curls of unlike phases, voxel 0.8: RK4 tangent " << 100.0 * eT << " %, helicoid " << 100.0 * eH << " %; Euler tangent "
              << 100.0 * eTe << " %, helicoid " << 100.0 * eHe << " %\n";
    // Measured: RK4 9.67 % against 11.43 % (0.85); with plain trilinear corner weights (power 1
    // instead of HelicoidFieldSampler::kCornerSharpness) the helicoid field gave 10.52 % (0.92).
    CHECK(eH < 0.9 * eT);
    CHECK(eHe < eTe);
}
