#include "../TestUtil.h"
#include "ScalpTestUtil.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/io/PointFile.h>
#include <vdbhair/io/StrandIO.h>
#include <vdbhair/io/VdbFile.h>
#include <vdbhair/render/SphereMesh.h>
#include <vdbhair/scalp/Follicles.h>
#include <vdbhair/scalp/RootGrid.h>
#include <vdbhair/scalp/ScalpRegion.h>
#include <vdbhair/scalp/ScalpSampler.h>
#include <vdbhair/scalp/ScalpSurface.h>

#include <openvdb/points/PointCount.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cstring>
#include <filesystem>

using namespace vdbhair;
using Catch::Matchers::Contains;

namespace {

openvdb::FloatGrid::Ptr unitSphere(const Vec3d& c, double r, double h)
{
    ScalpParams sp;
    sp.voxelSize = h;
    return scalpFromSphere(c, r, sp);
}

} // namespace

TEST_CASE("sampleFollicles: a sphere gets evenly spread roots on it", "[scalp]")
{
    const Vec3d c(0.25, -1.0, 2.0);
    const double r = 1.0, h = 0.05;
    const openvdb::FloatGrid::Ptr g = unitSphere(c, r, h);
    FollicleParams fp;
    fp.count = 1500;
    fp.seed = 3;
    const Follicles f = sampleFollicles(g, nullptr, fp);
    const FollicleStats st = measureFollicles(f.positions, g);
    std::cout << "sphere: " << f.positions.size() << " roots, area " << f.area << " (true " << 4 * M_PI * r * r << "), target spacing "
              << f.targetSpacing << ", NN mean " << st.nnMean << ", CV " << st.nnCV << ", iterations " << f.iterations
              << ", last move " << f.lastMove << ", max |phi| " << st.maxSurfaceDistanceVoxels << " voxels\n";
    CHECK(std::abs(double(f.positions.size()) - 1500.0) <= 0.02 * 1500.0);
    CHECK(f.area == Approx(4 * M_PI * r * r).epsilon(0.03));
    CHECK(st.nnCV < 0.1);
    double worstDist = 0.0, worstAngle = 0.0, worstTangent = 0.0;
    for (std::size_t i = 0; i < f.positions.size(); ++i) {
        const Vec3d p(f.positions[i]), radial = (p - c) / (p - c).length();
        worstDist = std::max(worstDist, std::abs((p - c).length() - r) / h);
        const double cosA = std::min(1.0, Vec3d(f.normals[i]).dot(radial));
        worstAngle = std::max(worstAngle, std::acos(cosA) * 180.0 / M_PI);
        worstTangent = std::max({worstTangent, std::abs(Vec3d(f.tangents[i]).dot(Vec3d(f.normals[i]))),
                                 std::abs(Vec3d(f.tangents[i]).length() - 1.0)});
    }
    CAPTURE(worstDist, worstAngle, worstTangent);
    CHECK(worstDist < 0.05);
    CHECK(worstAngle < 1.0);
    CHECK(worstTangent < 1e-5);
}

TEST_CASE("sampleFollicles: a band that never crosses zero gets no roots and no share of the count", "[scalp]")
{
    // A proper sphere and, beside it, a second sphere's band made unsigned (|phi|): what an open
    // part of a mesh that capping did not close looks like (head_max4's torso). The roots owed to
    // the unsigned part used to be redrawn onto the proper sphere, at half the spacing.
    const double r = 1.0, h = 0.05;
    const openvdb::FloatGrid::Ptr g = unitSphere(Vec3d(0.0), r, h);
    const openvdb::FloatGrid::Ptr other = unitSphere(Vec3d(3.0, 0.0, 0.0), r, h);
    {
        auto acc = g->getAccessor();
        for (auto it = other->cbeginValueOn(); it; ++it) acc.setValue(it.getCoord(), std::abs(*it));
    }
    FollicleParams fp;
    fp.count = 1500;
    const Follicles f = sampleFollicles(g, nullptr, fp);
    const FollicleStats st = measureFollicles(f.positions, g);
    std::cout << "sphere beside an unsigned band: " << f.positions.size() << " roots, area " << f.area << ", without a zero "
              << f.areaWithoutZero << " (each sphere " << 4 * M_PI * r * r << "), NN mean " << st.nnMean << ", CV " << st.nnCV << "\n";
    CHECK(f.area == Approx(4 * M_PI * r * r).epsilon(0.03));
    CHECK(f.areaWithoutZero > 0.5 * 4 * M_PI * r * r);
    // measureScalpArea (what `scalp` reports) counts as the sampler does.
    const ScalpArea measured = measureScalpArea(g, nullptr);
    CHECK(measured.area == f.area);
    CHECK(measured.areaWithoutZero == f.areaWithoutZero);
    CHECK(std::abs(double(f.positions.size()) - 1500.0) <= 0.02 * 1500.0);
    double farthest = 0.0;
    for (const Vec3f& p : f.positions) farthest = std::max(farthest, std::abs(Vec3d(p).length() - r) / h);
    CHECK(farthest < 0.05);  // every root on the proper sphere
    CHECK(st.nnCV < 0.1);
    CHECK(st.nnMean == Approx(f.targetSpacing * kRelaxedNearestPerSpacing).epsilon(0.05));
}

TEST_CASE("sampleFollicles: a cap region holds every root", "[scalp]")
{
    const Vec3d c(0.0);
    const double r = 1.0, h = 0.05, capRadius = 0.8;
    const openvdb::FloatGrid::Ptr g = unitSphere(c, r, h);
    const openvdb::BoolGrid::Ptr region = regionFromRoots(*g, {Vec3f(0.f, 1.1f, 0.f)}, capRadius, "pole");
    CHECK(region->getName() == "region");
    const Vec3d pole(0.0, 1.0, 0.0);
    FollicleParams fp;
    fp.spacing = 0.08;
    const Follicles f = sampleFollicles(g, region, fp);
    const FollicleStats st = measureFollicles(f.positions, g);
    // Cap area 2 pi r^2 (1 - cos a), sin(a/2) = capRadius / (2 r).
    const double a = 2.0 * std::asin(capRadius / (2.0 * r)), capArea = 2.0 * M_PI * r * r * (1.0 - std::cos(a));
    std::cout << "cap: " << f.positions.size() << " roots, area " << f.area << " (true " << capArea << "), NN mean " << st.nnMean
              << " (target " << fp.spacing << "), CV " << st.nnCV << ", iterations " << f.iterations << "\n";
    CHECK(f.area == Approx(capArea).epsilon(0.05));
    REQUIRE(f.positions.size() > 100);
    const ScalpSampler s(g, region);
    double farthest = 0.0;
    for (const Vec3f& p : f.positions) {
        CHECK(s.inRegion(Vec3d(p)));
        farthest = std::max(farthest, (Vec3d(p) - pole).length());
    }
    CHECK(farthest <= capRadius + 0.5 * std::sqrt(3.0) * h);
    CHECK(st.nnMean == Approx(fp.spacing).epsilon(0.1));
    CHECK(st.nnCV < 0.1);
    // Roots reach the rim (the contour's are on it; tested below).
    double outermost = 0.0;
    for (const Vec3f& p : f.positions) outermost = std::max(outermost, (Vec3d(p) - pole).length());
    std::cout << "cap: outermost root " << outermost << " (rim " << capRadius << ")\n";
    CHECK(outermost > capRadius - 0.5 * f.targetSpacing);
}

TEST_CASE("regionFromMask: a painted cap, as a float weight and as a bool mask on another transform", "[scalp]")
{
    const openvdb::FloatGrid::Ptr g = unitSphere(Vec3d(0.0), 1.0, 0.05);
    // A weight painted by height on a coarser grid of its own: 0 below y = 0.4, 1 above y = 0.6.
    openvdb::FloatGrid::Ptr weight = openvdb::FloatGrid::create(0.0f);
    weight->setTransform(openvdb::math::Transform::createLinearTransform(0.1));
    weight->setName("paint");
    openvdb::BoolGrid::Ptr mask = openvdb::BoolGrid::create(false);
    mask->setTransform(openvdb::math::Transform::createLinearTransform(0.07));
    {
        auto acc = weight->getAccessor();
        for (int i = -15; i <= 15; ++i)
            for (int j = -15; j <= 15; ++j)
                for (int k = -15; k <= 15; ++k) acc.setValue(openvdb::Coord(i, j, k), float(std::clamp((0.1 * j - 0.4) / 0.2, 0.0, 1.0)));
        auto b = mask->getAccessor();
        for (int i = -20; i <= 20; ++i)
            for (int j = -20; j <= 20; ++j)
                for (int k = -20; k <= 20; ++k)
                    if (0.07 * j > 0.5) b.setValue(openvdb::Coord(i, j, k), true);
    }
    const openvdb::BoolGrid::Ptr fromWeight = regionFromMask(*g, *weight, 0.5, "paint.vdb");
    const openvdb::BoolGrid::Ptr fromBool = regionFromMask(*g, *mask);
    CHECK(fromWeight->getName() == "region");
    CHECK(fromWeight->metaValue<std::string>("vdbhair_region_kind") == "mask");
    for (const openvdb::BoolGrid::Ptr& region : {fromWeight, fromBool}) {
        double lowest = 1e9, highestOutside = -1e9;
        for (auto it = region->cbeginValueOn(); it; ++it) lowest = std::min(lowest, g->indexToWorld(it.getCoord()).y());
        // Every band voxel above the cut is in: none is left out.
        const ScalpSampler s(g, region);
        for (auto it = g->cbeginValueOn(); it; ++it)
            if (std::abs(*it) < g->background() && !region->tree().isValueOn(it.getCoord()))
                highestOutside = std::max(highestOutside, g->indexToWorld(it.getCoord()).y());
        INFO("region voxels " << region->activeVoxelCount() << ", lowest " << lowest << ", highest outside " << highestOutside);
        CHECK(lowest > 0.5 - 0.08);
        CHECK(highestOutside < 0.5 + 0.08);
        CHECK(region->activeVoxelCount() > 100);
    }
    // Follicles in it stay above the cut.
    FollicleParams fp;
    fp.count = 300;
    for (const Vec3f& p : sampleFollicles(g, fromWeight, fp).positions) CHECK(p.y() > 0.5 - 0.08f);
    // What is refused.
    CHECK_THROWS_AS(regionFromMask(*g, *weight, 2.0), LookupError);  // a weight that never exceeds 2: empty
    CHECK_THROWS_AS(regionFromMask(*g, *openvdb::Vec3SGrid::create()), TypeError);
    CHECK_THROWS_AS(regionFromMask(*g, *weight, std::nan("")), ValueError);
}

TEST_CASE("regionFromVertexValues: a cap painted on a mesh's vertices, read from PLY colour and a named property", "[scalp]")
{
    // A sphere mesh whose vertices above y = 0.5 are painted: red 255 (uchar, scaled to 1) and
    // hair 2.0 (a float, as stored); the others red 0, hair 0.
    const TriangleMesh mesh = makeSphereMesh(Vec3d(0.0), 1.0, 48, 96);
    std::string ply = "ply\nformat ascii 1.0\nelement vertex " + std::to_string(mesh.vertices.size()) +
                      "\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\nproperty float hair\nelement face " +
                      std::to_string(mesh.triangles.size()) + "\nproperty list uchar int vertex_indices\nend_header\n";
    for (const Vec3f& v : mesh.vertices) {
        const bool painted = v.y() > 0.5f;
        ply += std::to_string(v.x()) + " " + std::to_string(v.y()) + " " + std::to_string(v.z()) + (painted ? " 255 2.0\n" : " 0 0.0\n");
    }
    for (const auto& t : mesh.triangles) ply += "3 " + std::to_string(t[0]) + " " + std::to_string(t[1]) + " " + std::to_string(t[2]) + "\n";
    const std::string path = test::writeBytes("painted_sphere.ply", ply);
    const std::vector<float> red = readPlyVertexValues(path, "red"), hair = readPlyVertexValues(path, "hair");
    REQUIRE(red.size() == mesh.vertices.size());
    CHECK(*std::max_element(red.begin(), red.end()) == 1.0f);  // uchar colour scaled to [0, 1]
    CHECK(*std::max_element(hair.begin(), hair.end()) == 2.0f);  // other properties as stored
    CHECK_THROWS_WITH(readPlyVertexValues(path, "green"), Contains("no scalar property 'green' (it has x, y, z, red, hair)"));

    const openvdb::FloatGrid::Ptr g = unitSphere(Vec3d(0.0), 1.0, 0.05);
    const TriangleMesh back = readTriangleMesh(path);
    for (const auto& [values, threshold] : {std::make_pair(red, 0.5), std::make_pair(hair, 1.0)}) {
        const openvdb::BoolGrid::Ptr region = regionFromVertexValues(*g, back, values, threshold, path);
        CHECK(region->getName() == "region");
        CHECK(region->metaValue<std::string>("vdbhair_region_kind") == "vertex");
        double lowest = 1e9, highestOutside = -1e9;
        for (auto it = region->cbeginValueOn(); it; ++it) lowest = std::min(lowest, g->indexToWorld(it.getCoord()).y());
        for (auto it = g->cbeginValueOn(); it; ++it)
            if (std::abs(*it) < g->background() && !region->tree().isValueOn(it.getCoord()))
                highestOutside = std::max(highestOutside, g->indexToWorld(it.getCoord()).y());
        // The rim lies between painted and unpainted vertices: within a ring of the mesh (1/48 of
        // the circumference, 0.065 in y near y = 0.5) and the band's half width.
        INFO("region voxels " << region->activeVoxelCount() << ", lowest " << lowest << ", highest outside " << highestOutside);
        CHECK(lowest > 0.5 - 0.2);
        CHECK(highestOutside < 0.5 + 0.2);
        CHECK(region->activeVoxelCount() > 100);
    }
    CHECK_THROWS_AS(regionFromVertexValues(*g, back, hair, 5.0), LookupError);  // nothing exceeds 5
    CHECK_THROWS_WITH(regionFromVertexValues(*g, back, std::vector<float>(3, 1.f)), Contains("3 values for"));
}

TEST_CASE("sampleFollicles: the same roots with 1 and 2 threads, bit for bit", "[scalp]")
{
    const openvdb::FloatGrid::Ptr g = unitSphere(Vec3d(0.0), 1.0, 0.05);
    FollicleParams fp;
    fp.count = 800;
    fp.seed = 11;
    Follicles one, two;
    {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
        one = sampleFollicles(g, nullptr, fp);
    }
    {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 2);
        two = sampleFollicles(g, nullptr, fp);
    }
    const Follicles serial = sampleFollicles(g, nullptr, fp, /*threaded=*/false);
    REQUIRE(one.positions.size() == two.positions.size());
    REQUIRE(one.positions.size() == serial.positions.size());
    const std::size_t bytes = one.positions.size() * sizeof(Vec3f);
    CHECK(std::memcmp(one.positions.data(), two.positions.data(), bytes) == 0);
    CHECK(std::memcmp(one.normals.data(), two.normals.data(), bytes) == 0);
    CHECK(std::memcmp(one.tangents.data(), two.tangents.data(), bytes) == 0);
    CHECK(std::memcmp(one.positions.data(), serial.positions.data(), bytes) == 0);
    fp.seed = 12;
    const Follicles other = sampleFollicles(g, nullptr, fp);
    CHECK(std::memcmp(one.positions.data(), other.positions.data(), bytes) != 0);
}

TEST_CASE("sampleFollicles: bad counts and regions", "[scalp]")
{
    const openvdb::FloatGrid::Ptr g = unitSphere(Vec3d(0.0), 1.0, 0.1);
    FollicleParams fp;
    CHECK_THROWS_WITH(sampleFollicles(g, nullptr, fp), Contains("give a count of at least 1 or a positive spacing"));
    fp.count = std::size_t(1) << 40;
    CHECK_THROWS_AS(sampleFollicles(g, nullptr, fp), LimitError);
    fp.count = 0;
    fp.spacing = 1e-6;
    CHECK_THROWS_WITH(sampleFollicles(g, nullptr, fp), Contains("more than the cap"));
    CHECK_THROWS_AS(regionFromRoots(*g, {Vec3f(50.f, 0.f, 0.f)}, 0.3, "far", std::uint64_t(1) << 28, 5.0), LookupError);
    CHECK_THROWS_AS(regionFromRoots(*g, {}, 0.3), ValueError);
}

TEST_CASE("writePlyPoints and createRootGrid: roots round trip through PLY and VDB points", "[scalp]")
{
    const openvdb::FloatGrid::Ptr g = unitSphere(Vec3d(0.0), 1.0, 0.1);
    FollicleParams fp;
    fp.count = 200;
    const Follicles f = sampleFollicles(g, nullptr, fp);
    OrientedPoints pts{f.positions, f.normals, f.tangents};
    const std::string ply = test::tempPath("roots.ply");
    writePlyPoints(ply, pts);
    const OrientedPoints back = readPlyPoints(ply);
    REQUIRE(back.size() == pts.size());
    CHECK(std::memcmp(back.positions.data(), pts.positions.data(), pts.size() * sizeof(Vec3f)) == 0);
    CHECK(std::memcmp(back.normals.data(), pts.normals.data(), pts.size() * sizeof(Vec3f)) == 0);
    CHECK(std::memcmp(back.tangents.data(), pts.tangents.data(), pts.size() * sizeof(Vec3f)) == 0);
    const openvdb::points::PointDataGrid::Ptr grid = createRootGrid(pts);
    CHECK(grid->getName() == "roots");
    CHECK(openvdb::points::pointCount(grid->tree()) == pts.size());
    CHECK(openvdb::points::pointCount(grid->tree(), openvdb::points::GroupFilter("root", grid->tree().cbeginLeaf()->attributeSet())) == pts.size());
    const auto& desc = grid->tree().cbeginLeaf()->attributeSet().descriptor();
    CHECK(desc.find("N") != openvdb::points::AttributeSet::INVALID_POS);
}

TEST_CASE("sampleFollicles: roots on the shared heads, in the region of a hairstyle's roots", "[scalp][data]")
{
    VDBHAIR_REQUIRE_SHARED_DATA();
    const std::string data = test::sharedData();
    struct Case { const char* head; const char* hair; };
    for (const Case& k : {Case{"scalp/ct2hair/Bangs_head.ply", "hair/cyhair/Bangs_100.hair"},
                          Case{"scalp/cem_yuksel/woman_head.ply", "hair/cyhair/straight.hair"},
                          Case{"scalp/usc_hairsalon/head_model.ply", ""}}) {
        const std::string headPath = data + "/" + k.head;
        if (!std::filesystem::exists(headPath)) { WARN("missing " << headPath); continue; }
        ScalpParams sp;
        const openvdb::FloatGrid::Ptr g = scalpFromMesh(readTriangleMesh(headPath), sp);
        openvdb::BoolGrid::Ptr region;
        std::vector<Vec3f> roots;
        if (*k.hair && std::filesystem::exists(data + "/" + k.hair)) {
            const StrandSet hair = readStrands(data + "/" + k.hair);
            for (std::size_t i = 0; i < hair.numStrands(); ++i) roots.push_back(hair.root(i));
            const double radius = std::max(2.0 * measureFollicles(roots).nnMean, 2.0 * g->voxelSize().x());
            region = regionFromRoots(*g, roots, radius, k.hair);
            // The region covers the hairstyle's roots (projected onto the surface).
            const ScalpSampler s(g, region);
            std::size_t covered = 0;
            for (const Vec3f& p : projectOntoSurface(*g, roots)) covered += s.inRegion(Vec3d(p)) ? 1 : 0;
            std::cout << k.head << ": region of " << k.hair << " (radius " << radius << "): " << region->activeVoxelCount() << " voxels, covers "
                      << covered << " of " << roots.size() << " roots\n";
            CHECK(double(covered) >= 0.99 * double(roots.size()));
        }
        FollicleParams fp;
        fp.count = 1000;  // the spread over a real head's region (the count rules are the sphere tests')
        const Follicles f = sampleFollicles(g, region, fp);
        const FollicleStats st = measureFollicles(f.positions, g);
        std::cout << k.head << ": " << f.positions.size() << " roots, area " << f.area << ", NN mean " << st.nnMean << ", CV " << st.nnCV
                  << ", iterations " << f.iterations << ", max |phi| " << st.maxSurfaceDistanceVoxels << " voxels\n";
        CHECK(f.positions.size() >= 970);
        CHECK(st.maxSurfaceDistanceVoxels < 0.1);
    }
}

TEST_CASE("sampleFollicles: fission from a quarter of the count and death from twice it reach the target", "[scalp]")
{
    const openvdb::FloatGrid::Ptr g = unitSphere(Vec3d(0.0), 1.0, 0.05);
    for (const double fraction : {0.25, 2.0}) {
        FollicleParams fp;
        fp.count = 1500;
        fp.initialFraction = fraction;
        const Follicles f = sampleFollicles(g, nullptr, fp);
        const FollicleStats st = measureFollicles(f.positions, g);
        std::cout << "sphere from " << f.initial << " particles: " << f.positions.size() << " roots, " << f.fissions << " fissions, " << f.deaths
                  << " deaths, last change at iteration " << f.lastPopulationChange << ", NN mean " << st.nnMean << ", CV " << st.nnCV
                  << ", radius spread " << f.radiusSpread << " sigma_hat\n";
        CHECK(f.initial == std::size_t(std::llround(fraction * 1500)));
        if (fraction < 1.0) CHECK(f.fissions >= 1100);
        else CHECK(f.deaths >= 1500);
        CHECK(std::abs(double(f.positions.size()) - 1500.0) <= 0.02 * 1500.0);
        CHECK(st.nnCV < 0.1);
        CHECK(st.nnMean == Approx(f.targetSpacing * kRelaxedNearestPerSpacing).epsilon(0.05));
        CHECK(st.maxSurfaceDistanceVoxels < 0.05);
        CHECK(f.lastPopulationChange > 0);
        CHECK(f.lastPopulationChange + fp.settleIterations <= fp.maxIterations);
    }
    // Without population control the count stays where it started.
    FollicleParams fp;
    fp.count = 1500;
    fp.initialFraction = 0.25;
    fp.controlInterval = 0;
    const Follicles f = sampleFollicles(g, nullptr, fp);
    CHECK(f.positions.size() == 375);
    CHECK(f.fissions == 0);
}

TEST_CASE("sampleFollicles: a radius left large splits, a squeezed one dies (Witkin & Heckbert's rules)", "[scalp]")
{
    // Half the count, and no count rule at work until the radii have grown: the sphere's
    // particles grow their radii until they split on their own (sigma > 1.5 sigma_hat).
    const openvdb::FloatGrid::Ptr g = unitSphere(Vec3d(0.0), 1.0, 0.05);
    FollicleParams fp;
    fp.count = 1000;
    fp.initialFraction = 0.2;  // radii start at sigma_hat / sqrt(0.2) = 2.24 sigma_hat: all above the fission threshold
    fp.maxIterations = 40;
    fp.settleIterations = 29;  // one control step, at iteration 10
    const Follicles f = sampleFollicles(g, nullptr, fp);
    std::cout << "one control step from 200 particles of radius 2.24 sigma_hat: " << f.positions.size() << " roots, " << f.fissions << " fissions\n";
    // The count rule alone would split at most half of the 200; the radius rule splits every calm one.
    CHECK(f.fissions > 100);
    CHECK(f.positions.size() == 200 + f.fissions - f.deaths);
}

TEST_CASE("sampleFollicles: the region's contour holds fixed roots on the cap's rim", "[scalp]")
{
    const Vec3d pole(0.0, 1.0, 0.0);
    const double h = 0.05, capRadius = 0.8;
    const openvdb::FloatGrid::Ptr g = unitSphere(Vec3d(0.0), 1.0, h);
    const openvdb::BoolGrid::Ptr region = regionFromRoots(*g, {Vec3f(0.f, 1.1f, 0.f)}, capRadius, "pole");
    FollicleParams fp;
    fp.spacing = 0.08;
    const Follicles f = sampleFollicles(g, region, fp);
    const FollicleStats st = measureFollicles(f.positions, g);
    REQUIRE(f.contour > 10);
    const double s = kRelaxedNearestPerSpacing * f.targetSpacing;  // the contour's spacing
    // The rim: chord capRadius from the pole, a circle of radius rr at height yr.
    const double yr = 1.0 - capRadius * capRadius / 2.0, rr = std::sqrt(1.0 - yr * yr);
    double worstOff = 0.0, closestContour = 1e9, closestFree = 1e9;
    for (std::size_t i = 0; i < f.contour; ++i) {
        worstOff = std::max(worstOff, std::abs((Vec3d(f.positions[i]) - pole).length() - capRadius));
        for (std::size_t j = 0; j < f.positions.size(); ++j) {
            if (j == i) continue;
            const double dij = (Vec3d(f.positions[i]) - Vec3d(f.positions[j])).length();
            if (j < f.contour) closestContour = std::min(closestContour, dij);
            else closestFree = std::min(closestFree, dij);
        }
    }
    // Every point of the rim has a contour root near it.
    double worstGap = 0.0;
    for (int k = 0; k < 720; ++k) {
        const double a = 2.0 * M_PI * k / 720.0;
        const Vec3d q(rr * std::cos(a), yr, rr * std::sin(a));
        double nearest = 1e9;
        for (std::size_t i = 0; i < f.contour; ++i) nearest = std::min(nearest, (Vec3d(f.positions[i]) - q).length());
        worstGap = std::max(worstGap, nearest);
    }
    std::cout << "cap contour: " << f.contour << " fixed of " << f.positions.size() << " (rim length " << 2 * M_PI * rr << " at spacing " << s
              << "), farthest from the rim " << worstOff / h << " voxels, rim point farthest from a contour root " << worstGap
              << ", contour-contour " << closestContour << ", contour-free " << closestFree << ", CV " << st.nnCV << "\n";
    CHECK(worstOff < 2.0 * h);  // the region is voxelized: its rim is within a voxel or so of the true one
    CHECK(worstGap < 0.75 * s + 2.0 * h);
    CHECK(double(f.contour) == Approx(2 * M_PI * rr / s).epsilon(0.25));
    CHECK(closestContour >= s * (1.0 - 1e-9));
    CHECK(closestFree >= 0.8 * s * (1.0 - 1e-9));
    CHECK(st.nnCV < 0.1);
    const ScalpSampler sampler(g, region);
    for (const Vec3f& p : f.positions) CHECK(sampler.inRegion(Vec3d(p)));
    // Without the contour: no fixed roots, and the rim less evenly lined.
    fp.contour = false;
    const Follicles free = sampleFollicles(g, region, fp);
    CHECK(free.contour == 0);
}

TEST_CASE("sampleFollicles: contour, fission and death give the same roots with 1 and 2 threads", "[scalp]")
{
    const openvdb::FloatGrid::Ptr g = unitSphere(Vec3d(0.0), 1.0, 0.05);
    const openvdb::BoolGrid::Ptr region = regionFromRoots(*g, {Vec3f(0.f, 1.1f, 0.f)}, 1.2, "pole");
    FollicleParams fp;
    fp.count = 500;
    fp.initialFraction = 0.4;
    fp.seed = 3;
    Follicles one, two;
    {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
        one = sampleFollicles(g, region, fp);
    }
    {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 2);
        two = sampleFollicles(g, region, fp);
    }
    REQUIRE(one.fissions > 0);
    REQUIRE(one.contour > 0);
    REQUIRE(one.positions.size() == two.positions.size());
    CHECK(one.fissions == two.fissions);
    CHECK(one.deaths == two.deaths);
    CHECK(std::memcmp(one.positions.data(), two.positions.data(), one.positions.size() * sizeof(Vec3f)) == 0);
}

TEST_CASE("sampleFollicles: Witkin & Heckbert parameters out of range", "[scalp]")
{
    const openvdb::FloatGrid::Ptr g = unitSphere(Vec3d(0.0), 1.0, 0.1);
    FollicleParams fp;
    fp.count = 10;
    fp.initialFraction = 0.0;
    CHECK_THROWS_WITH(sampleFollicles(g, nullptr, fp), Contains("initialFraction 0 must be in (0, 4]"));
    fp = FollicleParams{};
    fp.count = 10;
    fp.deathRatio = 1.0;
    CHECK_THROWS_WITH(sampleFollicles(g, nullptr, fp), Contains("deathRatio 1 must be in (0, 1)"));
    fp = FollicleParams{};
    fp.count = 10;
    fp.fissionRatio = 0.9;
    CHECK_THROWS_WITH(sampleFollicles(g, nullptr, fp), Contains("fissionRatio 0.9 must be above 1"));
    fp = FollicleParams{};
    fp.count = 10;
    fp.radiusStep = 0.5;
    CHECK_THROWS_AS(sampleFollicles(g, nullptr, fp), ValueError);
    fp = FollicleParams{};
    fp.count = 10;
    fp.alpha = std::nan("");
    CHECK_THROWS_AS(sampleFollicles(g, nullptr, fp), ValueError);
}
