#include "../TestUtil.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/field/FieldMapping.h>
#include <vdbhair/field/ScalpMap.h>
#include <vdbhair/field/StreamlineTracer.h>
#include <vdbhair/field/TangentField.h>
#include <vdbhair/io/VdbFile.h>
#include <vdbhair/render/SphereMesh.h>
#include <vdbhair/scalp/ScalpSurface.h>

#include <cmath>
#include <limits>
#include <random>

using namespace vdbhair;

namespace {

/// An ellipsoid head, semi-axes 1.3 (x), 1 (y), 1 (z) about the origin, as a level set made
/// from a mesh (a scalp that the sphere fitted to its roots does not describe: d from 1 to 1.3).
openvdb::FloatGrid::Ptr ellipsoidScalp()
{
    TriangleMesh mesh = makeSphereMesh(Vec3d(0.0), 1.0, 48, 96);
    for (Vec3f& v : mesh.vertices) v.x() *= 1.3f;
    ScalpParams params;
    params.voxelSize = 0.02;
    return scalpFromMesh(mesh, params);
}

/// The outward normal of the ellipsoid at a point on it.
Vec3d ellipsoidNormal(const Vec3d& p) { return Vec3d(p.x() / (1.3 * 1.3), p.y(), p.z()).unitSafe(); }

/// Straight strands of length 0.4 along the ellipsoid's normal from roots on its upper half.
StrandSet normalHair(int count)
{
    StrandSet s;
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> az(0.0, 2.0 * M_PI), y(0.2, 0.95);
    for (int i = 0; i < count; ++i) {
        const double h = y(rng), r = std::sqrt(1.0 - h * h), a = az(rng);
        const Vec3d root(1.3 * r * std::cos(a), h, r * std::sin(a));
        const Vec3d n = ellipsoidNormal(root);
        std::vector<Vec3f> pts;
        for (int k = 0; k < 21; ++k) pts.emplace_back(root + n * (0.02 * k));
        s.addStrand(pts.data(), pts.size());
    }
    return s;
}

std::vector<Vec3f> rootsOf(const StrandSet& s)
{
    std::vector<Vec3f> roots;
    for (std::size_t i = 0; i < s.numStrands(); ++i) roots.push_back(s.root(i));
    return roots;
}

} // namespace

TEST_CASE("ScalpMap: a map restored from its table is the same map", "[field]")
{
    const openvdb::FloatGrid::Ptr surface = ellipsoidScalp();
    ScalpSphere sphere;  // the unit sphere about the origin, y up
    const ScalpMap measured(sphere, *surface, ScalpMap::kFieldResolution);
    REQUIRE(measured.misses() == 0);
    const ScalpMap restored(sphere, measured.distances(), measured.resolution());
    REQUIRE(restored.hasSurface());
    std::mt19937 rng(1);
    std::uniform_real_distribution<double> a(-1.6, 1.6);
    int compared = 0;
    for (int i = 0; i < 2000; ++i) {
        const Vec3d p(a(rng), a(rng), a(rng));
        if (p.y() < -0.3 * p.length() || p.length() < 0.5) continue;  // away from the south pole and the centre
        const Vec3d s = measured.toScalp(p);
        CAPTURE(p, s);
        // Bit for bit: the mapping depends on the table alone.
        REQUIRE(restored.toScalp(p) == s);
        REQUIRE(restored.toWorld(s) == measured.toWorld(s));
        // Normals from the tabulated surface agree with the level set's gradient.
        REQUIRE(restored.frame(s.x(), s.y()).n.dot(measured.frame(s.x(), s.y()).n) > std::cos(3.0 * M_PI / 180.0));
        ++compared;
    }
    REQUIRE(compared > 1000);

    // Points on the ellipsoid are at w = 0 on the measured scalp (the facets and the bilinear
    // table within 0.005 radii), not on its sphere (up to 0.3).
    double worstMeasured = 0.0, worstSphere = 0.0;
    for (int i = 0; i < 500; ++i) {
        const double h = -0.2 + 1.15 * i / 500.0, r = std::sqrt(1.0 - h * h), az = 0.7 * i;
        const Vec3d p(1.3 * r * std::cos(az), h, r * std::sin(az));
        worstMeasured = std::max(worstMeasured, std::abs(measured.toScalp(p).z()));
        worstSphere = std::max(worstSphere, std::abs(worldToScalp(sphere, p).z()));
    }
    CHECK(worstMeasured < 0.005);
    CHECK(worstSphere > 0.25);

    std::vector<float> d = measured.distances();
    REQUIRE_THROWS_AS(ScalpMap(sphere, d, ScalpMap::kFieldResolution + 1), ValueError);  // size
    REQUIRE_THROWS_AS(ScalpMap(sphere, std::vector<float>(49, 1.0f), 7), ValueError);     // resolution
    d[100] = 0.0f;
    REQUIRE_THROWS_AS(ScalpMap(sphere, d, ScalpMap::kFieldResolution), ValueError);
    d[100] = std::numeric_limits<float>::quiet_NaN();
    REQUIRE_THROWS_AS(ScalpMap(sphere, d, ScalpMap::kFieldResolution), ValueError);
}

TEST_CASE("A scalp-space field over a measured scalp: roots at w = 0, the mapping rebuilt from the grids, retraced", "[field]")
{
    const openvdb::FloatGrid::Ptr surface = ellipsoidScalp();
    const StrandSet hair = normalHair(600);
    FieldParams fp;
    fp.voxelSize = 0.05;
    useScalpSpace(fp, rootsOf(hair), Vec3d(0.0, 1.0, 0.0), nullptr, surface);
    REQUIRE(fp.space == FieldSpace::Scalp);
    REQUIRE(fp.scalpSurface);
    REQUIRE(fp.scalpSurface->resolution() == ScalpMap::kFieldResolution);
    const TangentField field = estimateTangentField(hair, fp);

    // Every grid carries the table; the mapping read back from any of them is the one estimated with.
    const FieldMapping original(openvdb::math::Transform::createLinearTransform(fp.voxelSize / fp.scalpSphere().radius), fp.scalpSurface);
    const std::string path = test::tempPath("scalp_field.vdb");
    writeVdbGrids(path, field.grids(), "test");
    for (const openvdb::GridBase::ConstPtr& g : field.grids()) {
        CAPTURE(g->getName());
        const FieldMapping m = FieldMapping::fromGrid(*g);
        REQUIRE(m.scalpSurface());
        const FieldMapping fromFile = FieldMapping::fromGrid(*readVdbGrid(path, g->getName(), "test"));
        for (std::size_t i = 0; i < hair.numStrands(); i += 7) {
            const openvdb::Vec3d p(hair.root(i));
            REQUIRE(m.worldToIndex(p) == original.worldToIndex(p));
            REQUIRE(fromFile.worldToIndex(p) == original.worldToIndex(p));
        }
    }
    // The roots sit on the scalp: w (index z times the lattice spacing) is within a tenth of a voxel of 0.
    const double lattice = fp.voxelSize / fp.scalpSphere().radius;
    for (std::size_t i = 0; i < hair.numStrands(); ++i) {
        const double w = original.worldToIndex(openvdb::Vec3d(hair.root(i))).z() * lattice;
        REQUIRE(std::abs(w) < 0.1 * lattice);
    }

    // Retraced from the roots, the strands follow the normals they were made along.
    TraceParams tp;
    const StrandSet traced = retraceStrands(hair, *field.tangent, tp);
    REQUIRE(traced.numStrands() == hair.numStrands());
    double worst = 0.0;
    for (std::size_t i = 0; i < hair.numStrands(); ++i) {
        const Vec3d root(hair.root(i)), n = ellipsoidNormal(root);
        const Vec3d tip(traced.data(i)[traced.size(i) - 1]);
        worst = std::max(worst, ((tip - root) - n * n.dot(tip - root)).length());
    }
    CHECK(worst < 0.02);

    // Bad tables are refused with the grid's name and the rule.
    openvdb::GridBase::Ptr bad = field.tangent->deepCopyGrid();
    bad->insertMeta("vdbhair_scalp_distance", openvdb::StringMetadata("1 2 x"));
    REQUIRE_THROWS_AS(FieldMapping::fromGrid(*bad), FormatError);
    bad->insertMeta("vdbhair_scalp_distance", openvdb::StringMetadata("1 1 1"));
    REQUIRE_THROWS_AS(FieldMapping::fromGrid(*bad), FormatError);  // 3 values for 64²
    bad->removeMeta("vdbhair_scalp_resolution");
    REQUIRE_THROWS_AS(FieldMapping::fromGrid(*bad), FormatError);
    bad->insertMeta("vdbhair_scalp_resolution", openvdb::Int32Metadata(1 << 30));
    REQUIRE_THROWS_AS(FieldMapping::fromGrid(*bad), FormatError);

    // A centre outside the scalp and a sphere with a surface are refused.
    FieldParams other;
    std::vector<Vec3f> outside;
    for (const Vec3f& r : rootsOf(hair)) outside.push_back(r + Vec3f(3.0f, 0.0f, 0.0f));
    REQUIRE_THROWS_AS(useScalpSpace(other, outside, Vec3d(0.0, 1.0, 0.0), nullptr, surface), ValueError);
    ScalpSphere given;
    REQUIRE_THROWS_AS(useScalpSpace(other, rootsOf(hair), Vec3d(0.0, 1.0, 0.0), &given, surface), ValueError);
}
