#include "../TestUtil.h"
#include "ScalpTestUtil.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/io/MeshFile.h>
#include <vdbhair/scalp/Follicles.h>
#include <vdbhair/scalp/ScalpSampler.h>
#include <vdbhair/scalp/ScalpSurface.h>

#include <filesystem>

using namespace vdbhair;
using Catch::Matchers::Contains;

namespace {

/// Largest |phi| (in voxels) of @a grid at @a n points of the sphere (c, r).
double worstOnSphere(const openvdb::FloatGrid::Ptr& grid, const Vec3d& c, double r, std::size_t n = 500)
{
    const ScalpSampler s(grid);
    double worst = 0.0;
    for (const Vec3f& p : test::fibonacciSphere(n, c, r).positions) worst = std::max(worst, std::abs(s.distance(Vec3d(p))) / s.voxelSize());
    return worst;
}

} // namespace

TEST_CASE("scalpFromSphere: a level set named surface with vdbhair_ metadata", "[scalp]")
{
    ScalpParams sp;
    sp.voxelSize = 0.1;
    const openvdb::FloatGrid::Ptr g = scalpFromSphere(Vec3d(1, 2, 3), 2.0, sp);
    CHECK(g->getName() == "surface");
    CHECK(g->getGridClass() == openvdb::GRID_LEVEL_SET);
    CHECK(g->getCreator().rfind("vdbhair ", 0) == 0);
    CHECK(g->metaValue<std::string>("vdbhair_scalp_kind") == "sphere");
    CHECK(g->metaValue<double>("vdbhair_voxel_size") == Approx(0.1));
    for (auto it = g->beginMeta(); it != g->endMeta(); ++it) CHECK(it->first.find(':') == std::string::npos);
    CHECK(worstOnSphere(g, Vec3d(1, 2, 3), 2.0) < 0.05);
}

TEST_CASE("scalpFromSphere: refuses a band over the voxel cap, saying the estimate", "[scalp]")
{
    ScalpParams sp;
    sp.voxelSize = 1e-4;
    CHECK_THROWS_AS(scalpFromSphere(Vec3d(0.0), 1.0, sp), LimitError);
    CHECK_THROWS_WITH(scalpFromSphere(Vec3d(0.0), 1.0, sp), Contains("would make about") && Contains("more than the cap of 134217728"));
    CHECK_THROWS_AS(scalpFromSphere(Vec3d(0.0), -1.0, sp), ValueError);
}

TEST_CASE("scalpFromMesh: a closed sphere mesh and one open at the neck", "[scalp]")
{
    ScalpParams sp;
    sp.voxelSize = 0.05;
    const Vec3d c(0.5, 0.0, -0.25);
    ScalpMeshReport rep;
    const openvdb::FloatGrid::Ptr closed = scalpFromMesh(test::sphereMesh(c, 1.0), sp, &rep);
    CHECK(rep.boundaryEdges == 0);
    CHECK(rep.cappedLoops == 0);
    CHECK(closed->metaValue<std::string>("vdbhair_scalp_kind") == "mesh");
    // The polygon's chords are inside the sphere by up to r (1 - cos(pi/48)) = 0.002 = 0.04 voxel.
    CHECK(worstOnSphere(closed, c, 1.0) < 0.25);

    // Open below y = -0.7 r: one boundary loop, capped; the level set still has an inside.
    const openvdb::FloatGrid::Ptr open = scalpFromMesh(test::sphereMesh(c, 1.0, 32, 48, -0.7), sp, &rep);
    CHECK(rep.boundaryEdges == 48);
    CHECK(rep.cappedLoops == 1);
    CHECK(rep.openEdges == 0);
    const ScalpSampler s(open);
    CHECK(s.distance(c) < 0.0);
    CHECK(s.distance(c + Vec3d(0, 2, 0)) > 0.0);
    // Above the neck the surface is the sphere's.
    double worst = 0.0;
    for (const Vec3f& p : test::fibonacciSphere(500, c, 1.0).positions) {
        if (p.y() - c.y() > -0.6) worst = std::max(worst, std::abs(s.distance(Vec3d(p))) / s.voxelSize());
    }
    CHECK(worst < 0.25);
}

TEST_CASE("scalpFromMesh: bad meshes, each with its rule", "[scalp]")
{
    ScalpParams sp;
    sp.voxelSize = 0.05;
    CHECK_THROWS_WITH(scalpFromMesh(TriangleMesh{}, sp), Contains("the mesh has no triangles"));
    sp.voxelSize = 1e-5;
    CHECK_THROWS_AS(scalpFromMesh(test::sphereMesh(Vec3d(0.0), 1.0), sp), LimitError);
    // A single triangle has a boundary loop of 3 edges that capping closes into a flat pair:
    // no inside.
    TriangleMesh flat;
    flat.vertices = {Vec3f(0, 0, 0), Vec3f(1, 0, 0), Vec3f(0, 1, 0)};
    flat.triangles = {{0, 1, 2}};
    sp.voxelSize = 0.05;
    CHECK_THROWS_AS(scalpFromMesh(flat, sp), FormatError);
    CHECK_THROWS_WITH(scalpFromMesh(flat, sp), Contains("has no inside"));
}

TEST_CASE("scalpFromPoints: a sphere given as points agrees with the sphere", "[scalp]")
{
    ScalpParams sp;
    sp.voxelSize = 0.05;
    const Vec3d c(0.0, 1.0, 0.0);
    const openvdb::FloatGrid::Ptr g = scalpFromPoints(test::fibonacciSphere(400, c, 1.0), sp);
    CHECK(g->getGridClass() == openvdb::GRID_LEVEL_SET);
    CHECK(g->metaValue<std::string>("vdbhair_scalp_kind") == "points");
    const double worst = worstOnSphere(g, c, 1.0);
    std::cout << "scalpFromPoints: sphere of 400 points, worst |phi| on the true sphere " << worst << " voxels, "
              << g->activeVoxelCount() << " active voxels\n";
    CHECK(worst < 0.5);
    const ScalpSampler s(g);
    CHECK(s.distance(c) < 0.0);
    CHECK(s.distance(c + Vec3d(0, 1.5, 0)) > 0.0);
    OrientedPoints few = test::fibonacciSphere(4, c, 1.0);
    CHECK_THROWS_WITH(scalpFromPoints(few, sp), Contains("4 constraint points"));
    OrientedPoints noNormals = test::fibonacciSphere(10, c, 1.0);
    noNormals.normals.clear();
    CHECK_THROWS_WITH(scalpFromPoints(noNormals, sp), Contains("no normals"));
}

TEST_CASE("scalpFromMesh: the shared heads become closed level sets", "[scalp][data]")
{
    VDBHAIR_REQUIRE_SHARED_DATA();
    const std::string dir = test::sharedData() + "/scalp";
    for (const char* name : {"ct2hair/Bangs_head.ply", "usc_hairsalon/head_model.ply", "cem_yuksel/woman_head.ply",
                             "sintel/sintel.obj", "tressfx/head_max4.obj", "tressfx/ruby_head.obj"}) {
        const std::string path = dir + "/" + name;
        if (!std::filesystem::exists(path)) { WARN("missing " << path); continue; }
        const TriangleMesh mesh = readTriangleMesh(path);
        ScalpParams sp;
        sp.source = name;
        ScalpMeshReport rep;
        const openvdb::FloatGrid::Ptr g = scalpFromMesh(mesh, sp, &rep);
        // How many of the mesh's vertices are on the zero level set (within one voxel)?
        const ScalpSampler s(g);
        std::size_t near = 0;
        for (const Vec3f& v : mesh.vertices) near += std::abs(s.distance(Vec3d(v))) < s.voxelSize() ? 1 : 0;
        const double frac = double(near) / double(mesh.vertices.size());
        std::cout << "scalp " << name << ": voxel " << s.voxelSize() << ", " << g->activeVoxelCount() << " voxels, welded "
                  << rep.weldedVertices << ", boundary edges " << rep.boundaryEdges << ", capped loops " << rep.cappedLoops
                  << ", open edges " << rep.openEdges << ", non-manifold " << rep.nonManifoldEdges << "; vertices within a voxel of zero: "
                  << 100.0 * frac << " %\n";
        CAPTURE(name, frac);
        CHECK(frac > 0.5);
    }
}
