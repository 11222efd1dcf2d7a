#include "../TestUtil.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/field/TangentField.h>
#include <vdbhair/strands/Frames.h>

#include <openvdb/tools/Count.h>
#include <tbb/global_control.h>

#include <cstring>
#include <limits>
#include <random>

using namespace vdbhair;
using Catch::Matchers::Contains;

namespace {

/// A bundle of parallel straight strands along @a dir, rooted on a grid in the plane through the origin.
StrandSet parallelStrands(const Vec3f& dir, int side, float spacing, float length, std::size_t vertices)
{
    StrandSet s;
    const Vec3f a = perpendicularTo(dir), b = dir.cross(a);
    for (int i = 0; i < side; ++i) {
        for (int j = 0; j < side; ++j) {
            const Vec3f root = a * (float(i) * spacing) + b * (float(j) * spacing) + Vec3f(0.013f, 0.027f, 0.041f);
            std::vector<Vec3f> pts;
            for (std::size_t k = 0; k < vertices; ++k) pts.push_back(root + dir * (length * float(k) / float(vertices - 1)));
            s.addStrand(pts);
        }
    }
    return s;
}

/// @a count random walks of @a steps steps, mostly along +x, rooted around the origin.
StrandSet randomWalks(unsigned seed, int count, int steps)
{
    StrandSet s;
    std::mt19937 rng(seed);
    std::normal_distribution<float> n(0.f, 1.f);
    for (int i = 0; i < count; ++i) {
        std::vector<Vec3f> pts{Vec3f(n(rng), n(rng), n(rng))};
        for (int k = 0; k < steps; ++k) pts.push_back(pts.back() + Vec3f(0.3f + 0.1f * n(rng), 0.1f * n(rng), 0.1f * n(rng)));
        s.addStrand(pts);
    }
    return s;
}

} // namespace

TEST_CASE("estimateTangentField: a straight parallel hairstyle gives a uniform field", "[field]")
{
    const Vec3f dir = Vec3f(1.f, 2.f, -0.5f).unitSafe();
    const StrandSet s = parallelStrands(dir, 5, 0.7f, 10.f, 6);  // segments of 2 cross several voxels
    FieldParams p;
    p.voxelSize = 0.5;
    const TangentField f = estimateTangentField(s, p);
    REQUIRE(f.tangent->activeVoxelCount() > 0);
    for (auto it = f.tangent->cbeginValueOn(); it; ++it) REQUIRE(((*it) - dir).length() < 1e-6f);
    // hair_length: the total length, distributed over the voxels the strands pass.
    double total = 0.0;
    for (auto it = f.hairLength->cbeginValueOn(); it; ++it) total += *it;
    REQUIRE(total == Approx(25 * 10.0).epsilon(1e-5));
    REQUIRE(f.tangent->activeVoxelCount() == f.density->activeVoxelCount());
    REQUIRE(f.tangent->getName() == "tangent");
    REQUIRE(f.density->getName() == "density");
    REQUIRE(f.tangent->getVectorType() == openvdb::VEC_CONTRAVARIANT_RELATIVE);
    REQUIRE(f.density->getGridClass() == openvdb::GRID_FOG_VOLUME);
    REQUIRE(f.hairLength->getName() == "hair_length");
    REQUIRE(f.hairLength->getGridClass() == openvdb::GRID_UNKNOWN);
    REQUIRE(f.tangent->metaValue<double>("vdbhair_voxel_size") == 0.5);
    REQUIRE(f.tangent->metaValue<int>("vdbhair_iterations") == 2);
    REQUIRE(f.tangent->metaValue<std::string>("vdbhair_space") == "world");
}

TEST_CASE("estimateTangentField: a segment marks every voxel it passes, and no other", "[field]")
{
    StrandSet s;
    s.addStrand(std::vector<Vec3f>{Vec3f(0.1f, 0.2f, 0.3f), Vec3f(10.1f, 0.2f, 0.3f)});  // one segment, 11 voxels
    FieldParams p;
    p.voxelSize = 1.0;
    const TangentField f = estimateTangentField(s, p);
    REQUIRE(f.tangent->activeVoxelCount() == 11);
    for (int i = 0; i <= 10; ++i) REQUIRE(f.tangent->tree().isValueOn(openvdb::Coord(i, 0, 0)));
    REQUIRE(f.hairLength->tree().getValue(openvdb::Coord(5, 0, 0)) == Approx(1.0));
    REQUIRE(f.hairLength->tree().getValue(openvdb::Coord(0, 0, 0)) == Approx(0.4));
    REQUIRE_FALSE(f.tangent->tree().isValueOn(openvdb::Coord(0, 1, 0)));
}

TEST_CASE("estimateTangentField: Eq. 9 suppresses an outlier crossing a coherent bundle", "[field]")
{
    // A bundle along x and one strand along y through it: the voxels they share get a plain
    // average tilted towards y; the reweighted estimate stays closer to x.
    StrandSet s;
    for (int k = 0; k < 4; ++k) {
        s.addStrand(std::vector<Vec3f>{Vec3f(-5.f, 0.05f * float(k), 0.f), Vec3f(5.f, 0.05f * float(k), 0.f)});
    }
    s.addStrand(std::vector<Vec3f>{Vec3f(0.f, -5.f, 0.f), Vec3f(0.f, 5.f, 0.f)});
    FieldParams plain, robust;
    plain.voxelSize = robust.voxelSize = 1.0;
    plain.iterations = 1;  // v1: the plain (length-weighted) average
    robust.iterations = 2;
    const auto vp = estimateTangentField(s, plain).tangent->tree().getValue(openvdb::Coord(0, 0, 0));
    const auto vr = estimateTangentField(s, robust).tangent->tree().getValue(openvdb::Coord(0, 0, 0));
    const double anglePlain = std::acos(std::min(1.f, vp.x())), angleRobust = std::acos(std::min(1.f, vr.x()));
    CAPTURE(vp, vr, anglePlain, angleRobust);
    // Plain average of four x and one y of equal length: atan(1/4).
    REQUIRE(anglePlain == Approx(std::atan(0.25)).epsilon(1e-5));
    REQUIRE(angleRobust < 0.75 * anglePlain);
    // Eq. 9 by hand: weights 0.5(T.v1 + 1) for the 4 x and the 1 y strands.
    const double c = std::cos(anglePlain), s1 = std::sin(anglePlain);
    const double wx = 0.5 * (c + 1.0), wy = 0.5 * (s1 + 1.0);
    REQUIRE(std::atan2(wy, 4.0 * wx) == Approx(angleRobust).epsilon(1e-5));
    // And more iterations move further from the outlier.
    FieldParams more = robust;
    more.iterations = 5;
    const auto v5 = estimateTangentField(s, more).tangent->tree().getValue(openvdb::Coord(0, 0, 0));
    REQUIRE(std::acos(std::min(1.f, v5.x())) < angleRobust);
}

TEST_CASE("estimateTangentField: opposing strands cancel to a zero vector in an active voxel", "[field]")
{
    StrandSet s;
    s.addStrand(std::vector<Vec3f>{Vec3f(-0.4f, 0.f, 0.f), Vec3f(0.4f, 0.f, 0.f)});
    s.addStrand(std::vector<Vec3f>{Vec3f(0.4f, 0.f, 0.f), Vec3f(-0.4f, 0.f, 0.f)});
    FieldParams p;
    p.voxelSize = 1.0;
    const TangentField f = estimateTangentField(s, p);
    REQUIRE(f.tangent->tree().isValueOn(openvdb::Coord(0)));
    REQUIRE(f.tangent->tree().getValue(openvdb::Coord(0)) == openvdb::Vec3f(0.f));
    REQUIRE(f.hairLength->tree().getValue(openvdb::Coord(0)) == Approx(1.6));
}

TEST_CASE("estimateTangentField: bitwise identical with 1 and 2 threads", "[field]")
{
    const StrandSet s = randomWalks(11, 3000, 12);
    FieldParams p;
    p.voxelSize = 0.25;
    TangentField one, two;
    {
        tbb::global_control c(tbb::global_control::max_allowed_parallelism, 1);
        one = estimateTangentField(s, p);
    }
    {
        tbb::global_control c(tbb::global_control::max_allowed_parallelism, 2);
        two = estimateTangentField(s, p);
    }
    REQUIRE(one.tangent->activeVoxelCount() == two.tangent->activeVoxelCount());
    auto acc = two.tangent->getConstAccessor();
    auto dacc = two.density->getConstAccessor();
    for (auto it = one.tangent->cbeginValueOn(); it; ++it) {
        REQUIRE(acc.isValueOn(it.getCoord()));
        REQUIRE(std::memcmp(&(*it), &acc.getValue(it.getCoord()), sizeof(openvdb::Vec3f)) == 0);
        const float d1 = one.density->tree().getValue(it.getCoord()), d2 = dacc.getValue(it.getCoord());
        REQUIRE(std::memcmp(&d1, &d2, sizeof(float)) == 0);
    }
}

TEST_CASE("estimateTangentField: the same grids with or without the memory check, and without coherence and spread", "[field]")
{
    // The memory check measures the vertices' extent and the estimate reuses it; with no memory
    // limit the estimate measures it itself. coherenceAndSpread = false leaves out two grids only.
    const StrandSet s = randomWalks(13, 2000, 10);
    FieldParams checked;
    checked.voxelSize = 0.2;
    FieldParams unchecked = checked;
    unchecked.maxMemory = std::numeric_limits<std::uint64_t>::max();
    FieldParams lean = checked;
    lean.coherenceAndSpread = false;
    const std::vector<TangentField> a = estimateTangentFieldLevels(s, checked, 2), b = estimateTangentFieldLevels(s, unchecked, 2),
                                    c = estimateTangentFieldLevels(s, lean, 2);
    for (std::size_t l = 0; l < 2; ++l) {
        CAPTURE(l);
        REQUIRE(c[l].coherence == nullptr);
        REQUIRE(c[l].spread == nullptr);
        REQUIRE(c[l].grids().size() == 3);
        REQUIRE(a[l].coherence != nullptr);
        REQUIRE(a[l].tangent->activeVoxelCount() > 1000);
        for (const TangentField* other : {&b[l], &c[l]}) {
            REQUIRE(other->tangent->activeVoxelCount() == a[l].tangent->activeVoxelCount());
            REQUIRE(other->tangent->tree().leafCount() == a[l].tangent->tree().leafCount());
            auto acc = other->tangent->getConstAccessor();
            auto dacc = other->density->getConstAccessor();
            auto hacc = other->hairLength->getConstAccessor();
            for (auto it = a[l].tangent->cbeginValueOn(); it; ++it) {
                REQUIRE(acc.isValueOn(it.getCoord()));
                REQUIRE(std::memcmp(&(*it), &acc.getValue(it.getCoord()), sizeof(openvdb::Vec3f)) == 0);
                const float d1 = a[l].density->tree().getValue(it.getCoord()), d2 = dacc.getValue(it.getCoord());
                REQUIRE(std::memcmp(&d1, &d2, sizeof(float)) == 0);
                const float h1 = a[l].hairLength->tree().getValue(it.getCoord()), h2 = hacc.getValue(it.getCoord());
                REQUIRE(std::memcmp(&h1, &h2, sizeof(float)) == 0);
            }
        }
        const auto& bc = b[l].coherence->tree();
        for (auto it = a[l].coherence->cbeginValueOn(); it; ++it) REQUIRE(bc.getValue(it.getCoord()) == *it);
    }
}

TEST_CASE("estimateTangentFieldLevels: level l has voxel size h*2^l and its own names", "[field]")
{
    const StrandSet s = parallelStrands(Vec3f(0, 0, 1), 3, 0.5f, 8.f, 9);
    FieldParams p;
    p.voxelSize = 0.25;
    const auto levels = estimateTangentFieldLevels(s, p, 3);
    REQUIRE(levels.size() == 3);
    for (int l = 0; l < 3; ++l) {
        REQUIRE(levels[std::size_t(l)].tangent->getName() == "tangent_level_" + std::to_string(l));
        REQUIRE(levels[std::size_t(l)].density->getName() == "density_level_" + std::to_string(l));
        REQUIRE(levels[std::size_t(l)].hairLength->getName() == "hair_length_level_" + std::to_string(l));
        REQUIRE(levels[std::size_t(l)].densityReference == levels[0].densityReference);  // one meaning for every level
        REQUIRE(levels[std::size_t(l)].tangent->voxelSize().x() == Approx(0.25 * (1 << l)));
        REQUIRE(levels[std::size_t(l)].tangent->metaValue<int>("vdbhair_level") == l);
    }
    REQUIRE(levels[2].tangent->activeVoxelCount() < levels[0].tangent->activeVoxelCount());
}

TEST_CASE("estimateTangentField: voxel size 0 is the library's suggestion, at every level", "[field]")
{
    const StrandSet s = parallelStrands(Vec3f(1, 0, 0), 6, 2.f, 10.f, 5);
    FieldParams p;
    REQUIRE(p.voxelSize == 0.0);
    const double h = suggestVoxelSize(s);
    REQUIRE(resolveVoxelSize(s, p) == h);
    REQUIRE(estimateTangentField(s, p).tangent->voxelSize().x() == Approx(h).epsilon(1e-12));
    const std::vector<TangentField> levels = estimateTangentFieldLevels(s, p, 2);
    REQUIRE(levels[1].tangent->voxelSize().x() == Approx(2.0 * h).epsilon(1e-12));
    p.voxelSize = 0.5;
    REQUIRE(resolveVoxelSize(s, p) == 0.5);
    REQUIRE_THROWS_WITH(estimateTangentFieldLevels(s, p, FieldParams::kMaxLevels + 1),
                        Contains("levels " + std::to_string(FieldParams::kMaxLevels + 1) + " must be between 1 and " +
                                 std::to_string(FieldParams::kMaxLevels)));
}

TEST_CASE("estimateTangentField: bad parameters are clear errors before any work", "[field]")
{
    const StrandSet s = parallelStrands(Vec3f(1, 0, 0), 2, 1.f, 100.f, 3);
    FieldParams p;
    p.voxelSize = -1.0;
    REQUIRE_THROWS_WITH(estimateTangentField(s, p), Contains("voxel size -1.000000 must be a positive finite length"));
    p.voxelSize = 1e-4;  // 4 strands of 2 segments of 50: 8 x (5e5 + 1) visits
    p.maxVoxels = 1000000;
    REQUIRE_THROWS_AS(estimateTangentField(s, p), LimitError);
    // The library names its parameter (a ParamError): what() in Python's spelling, the command line's is --max-voxels.
    REQUIRE_THROWS_WITH(estimateTangentField(s, p), Contains("voxel size 0.000100 needs up to 40000") &&
                                                        Contains("voxel visits, more than the cap of 1000000 (raise max_voxels"));
    p.maxVoxels = FieldParams().maxVoxels;
    p.voxelSize = 1e-6;
    REQUIRE_THROWS_WITH(estimateTangentField(s, p), Contains("below OpenVDB's smallest voxel size"));
    p.voxelSize = 1.0;
    p.iterations = 0;
    REQUIRE_THROWS_AS(estimateTangentField(s, p), ValueError);
    p.iterations = 2;
    REQUIRE_THROWS_WITH(estimateTangentField(StrandSet{}, p), Contains("the hairstyle has no strands"));
    StrandSet far = s;
    for (Vec3f& v : far.positions) v += Vec3f(1e6f, 0.f, 0.f);
    p.voxelSize = 1e-4;
    p.maxVoxels = std::uint64_t(1) << 62;
    REQUIRE_THROWS_WITH(estimateTangentField(far, p), Contains("beyond the grid's index range"));
}

TEST_CASE("estimateTangentField: density is a fog volume in [0, 1], the same at any voxel size for a given reference", "[field]")
{
    // A block of parallel strands 0.1 apart: hair length per unit volume 1 / 0.1^2 = 100 inside.
    StrandSet s;
    for (int i = 0; i < 40; ++i)
        for (int j = 0; j < 40; ++j) {
            const Vec3f root(0.025f + 0.1f * float(i), 0.025f + 0.1f * float(j), 0.f);
            s.addStrand(std::vector<Vec3f>{root, root + Vec3f(0.f, 0.f, 4.f)});
        }
    for (const double h : {0.5, 1.0}) {
        CAPTURE(h);
        FieldParams p;
        p.voxelSize = h;
        p.densityReference = 200.0;  // length per unit volume that counts as 1
        const TangentField f = estimateTangentField(s, p);
        REQUIRE(f.density->metaValue<double>("vdbhair_density_reference") == 200.0);
        // A voxel well inside the block holds 100 / 200 = 0.5 whatever its size.
        const openvdb::Coord inside = f.density->transform().worldToIndexCellCentered(openvdb::Vec3d(2.0, 2.0, 2.0));
        REQUIRE(f.density->tree().getValue(inside) == Approx(0.5).epsilon(1e-3));
        REQUIRE(f.hairLength->tree().getValue(inside) == Approx(100.0 * h * h * h).epsilon(1e-3));
        for (auto it = f.density->cbeginValueOn(); it; ++it) REQUIRE((*it >= 0.f && *it <= 1.f));
    }
    // Chosen reference: the 95th percentile of length per volume, so the densest voxels are 1.
    FieldParams p;
    p.voxelSize = 0.5;
    const TangentField f = estimateTangentField(s, p);
    REQUIRE(f.densityReference == Approx(100.0).epsilon(1e-3));
    float maxDensity = 0.f;
    for (auto it = f.density->cbeginValueOn(); it; ++it) maxDensity = std::max(maxDensity, *it);
    REQUIRE(maxDensity == Approx(1.f).epsilon(1e-3));
    p.densityReference = -1.0;
    REQUIRE_THROWS_WITH(estimateTangentField(s, p), Contains("density reference"));
}

TEST_CASE("estimateFieldFootprint: the leaves counted before the estimate are the field's leaves", "[field]")
{
    // Random walks of random step lengths (some segments cross several blocks, some stay in one
    // voxel, some have zero length), at voxel sizes from far below to above a step.
    std::mt19937 rng(12);
    std::uniform_real_distribution<float> u(-1.f, 1.f);
    for (int trial = 0; trial < 9; ++trial) {
        StrandSet s;
        const float stepLength = trial % 3 == 0 ? 0.05f : trial % 3 == 1 ? 0.5f : 3.f;
        for (int i = 0; i < 16; ++i) {
            std::vector<Vec3f> pts{Vec3f(5.f * u(rng), 5.f * u(rng), 5.f * u(rng))};
            for (int j = 0; j < 30; ++j) pts.push_back(j == 7 ? pts.back() : pts.back() + stepLength * Vec3f(u(rng), u(rng), u(rng)));
            s.addStrand(pts);
        }
        FieldParams p;
        p.voxelSize = trial < 3 ? 0.03 : trial < 6 ? 0.2 : 1.1;
        CAPTURE(trial, stepLength, p.voxelSize);
        const FieldFootprint f = estimateFieldFootprint(s, p);
        const TangentField field = estimateTangentField(s, p);
        CHECK(f.leaves == field.tangent->tree().leafCount());
        CHECK(f.strands == s.numStrands());
        CHECK(f.vertices == s.numVertices());
        CHECK(f.visits >= field.tangent->activeVoxelCount());
        // The bytes grow with every term.
        FieldFootprint more = f;
        more.leaves += 1;
        CHECK(estimatePeakBytes({more}, MemoryUse::Field) > estimatePeakBytes({f}, MemoryUse::Field));
    }
}

TEST_CASE("estimateTangentField: an estimate above maxMemory is refused before any work", "[field]")
{
    const StrandSet s = parallelStrands(Vec3f(1, 0, 0), 3, 0.5f, 10.f, 20);
    FieldParams p;
    p.voxelSize = 0.25;
    p.maxMemory = 1000;
    REQUIRE_THROWS_AS(estimateTangentField(s, p), LimitError);
    // A refusal names the leaves counted exactly (the check bounds them by their box first).
    const FieldFootprint exact = estimateFieldFootprint(s, p);
    REQUIRE(exact.leaves > 0);
    REQUIRE_THROWS_WITH(estimateTangentField(s, p), Contains(", " + std::to_string(exact.leaves) + " leaves at voxel size "));
    // The estimate, its terms, what is available and the rule, naming the library's parameter.
    REQUIRE_THROWS_WITH(estimateTangentFieldLevels(s, p, 2),
                        Contains("estimateTangentField: needs about ") && Contains(" MiB (9 strands, 180 vertices, ") &&
                            Contains("more than the 1000 B of max_memory; a request whose estimate exceeds the memory it may use is refused"));
    p.maxMemory = estimatePeakBytes({estimateFieldFootprint(s, p)}, MemoryUse::Field);  // exactly enough
    CHECK(estimateTangentField(s, p).tangent->activeVoxelCount() > 0);
    p.maxMemory = 0;  // the memory available now: ample for nine strands
    CHECK(availableMemoryBytes(p) > (std::uint64_t(64) << 20));
    CHECK_NOTHROW(estimateTangentField(s, p));
}
