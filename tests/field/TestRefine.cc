// Tests of vdbhair/field/Refine.h, ConsistentRetrace.h, HeadObstacle.h and RefineReport.h.
#include "TestUtil.h"

#include <vdbhair/field/ConsistentRetrace.h>
#include <vdbhair/field/HairVolume.h>
#include <vdbhair/field/Refine.h>
#include <vdbhair/io/StrandIO.h>
#include <vdbhair/strands/Measures.h>

#include <cmath>
#include <random>

using namespace vdbhair;
using Catch::Matchers::Contains;

namespace {

/// A straight strand from @a root along @a dir, @a n vertices over @a length.
std::vector<Vec3f> line(const Vec3f& root, Vec3f dir, float length, std::size_t n)
{
    dir.normalize();
    std::vector<Vec3f> p(n);
    for (std::size_t i = 0; i < n; ++i) p[i] = root + dir * (length * float(i) / float(n - 1));
    return p;
}

/// A bundle of parallel straight strands along +x, roots on a square grid of side @a side in the
/// x = 0 plane, @a perSide strands to a side.
StrandSet bundle(int perSide, float side, float length, std::size_t n)
{
    StrandSet s;
    for (int j = 0; j < perSide; ++j) {
        for (int k = 0; k < perSide; ++k) {
            const Vec3f root(0.f, side * (float(j) + 0.5f) / float(perSide), side * (float(k) + 0.5f) / float(perSide));
            s.addStrand(line(root, Vec3f(1.f, 0.f, 0.f), length, n));
        }
    }
    return s;
}

double maxDisplacement(const StrandSet& a, const StrandSet& b, std::size_t strand)
{
    double m = 0.0;
    for (std::size_t j = 0; j < a.size(strand); ++j) m = std::max(m, double((a.data(strand)[j] - b.data(strand)[j]).length()));
    return m;
}

Vec3f unitDir(const StrandSet& s, std::size_t i, std::size_t j)
{
    Vec3f d = s.data(i)[j + 1] - s.data(i)[j];
    d.normalize();
    return d;
}

} // namespace

TEST_CASE("refineStrands: outliers crossing a coherent bundle are pulled into its flow, inliers stay, with every integrator", "[field]")
{
    StrandSet s = bundle(20, 2.f, 10.f, 41);
    const std::size_t inliers = s.numStrands();
    // Three strands that start inside the bundle and head off at 25-35 degrees from it.
    const float angles[3] = {25.f, 30.f, 35.f};
    for (int k = 0; k < 3; ++k) {
        const float a = angles[k] * float(M_PI) / 180.f;
        s.addStrand(line(Vec3f(0.f, 0.35f + 0.5f * float(k), 1.05f), Vec3f(std::cos(a), k == 1 ? -std::sin(a) : std::sin(a), 0.f), 10.f, 41));
    }
    // The consistent retrace steps through the engine (Streamline.h): every integrator keeps the
    // inliers and corrects the outliers.
    const Integrator integ = GENERATE(Integrator::Euler, Integrator::RK2, Integrator::RK3, Integrator::RK4);
    CAPTURE(integratorName(integ));
    RefineParams rp;
    rp.field.voxelSize = 0.5;
    rp.head = HeadObstacle::none();
    rp.setStep(0.0, integ);
    rp.measure = true;
    const RefineResult r = refineStrands(s, rp);
    const double voxel = 0.5;
    double worstInlier = 0.0;
    for (std::size_t i = 0; i < inliers; ++i) worstInlier = std::max(worstInlier, maxDisplacement(s, r.strands, i));
    CAPTURE(worstInlier);
    REQUIRE(worstInlier < 0.1 * voxel);
    for (std::size_t i = inliers; i < s.numStrands(); ++i) {
        CAPTURE(i);
        // Pulled toward the flow: the tip is closer to the bundle's axis line than it was, and
        // the strand runs along +x where it is inside the bundle.
        const Vec3f tipIn = s.tip(i), tipOut = r.strands.tip(i);
        const float offIn = std::abs(tipIn.y() - 1.f), offOut = std::abs(tipOut.y() - 1.f);
        CAPTURE(offIn, offOut);
        REQUIRE(offOut < 0.5f * offIn);
        REQUIRE(unitDir(r.strands, i, 20).x() > std::cos(10.0 * M_PI / 180.0));
        REQUIRE(polylineLength(r.strands.data(i), r.strands.size(i)) == Approx(10.0).epsilon(1e-5));
    }
    const RefineMeasures& m = r.levels.front().measures;
    REQUIRE(m.fullLength == s.numStrands());
    REQUIRE(m.leftVolume == 0);
    REQUIRE(r.levels.front().consistency.corrected == 3);
    REQUIRE(m.coherenceAfter > m.coherenceBefore);
}

TEST_CASE("HairVolume: the strands' voxels dilated by one, tested every half voxel", "[field]")
{
    StrandSet s;
    s.addStrand(line(Vec3f(0.f), Vec3f(1.f, 0.f, 0.f), 10.f, 11));
    FieldParams fp;
    fp.voxelSize = 0.5;
    const TangentField f = estimateTangentField(s, fp);
    const HairVolume v(*f.tangent);
    HairVolume::Probe probe(v);
    const std::vector<Vec3f> same = line(Vec3f(0.f), Vec3f(1.f, 0.f, 0.f), 10.f, 2);
    const std::vector<Vec3f> oneOff = line(Vec3f(0.f, 0.5f, 0.f), Vec3f(1.f, 0.f, 0.f), 10.f, 2);   // the dilation
    const std::vector<Vec3f> twoOff = line(Vec3f(0.f, 1.0f, 0.f), Vec3f(1.f, 0.f, 0.f), 10.f, 2);   // beyond it
    REQUIRE(probe.containsPolyline(same.data(), same.size()));
    REQUIRE(probe.containsPolyline(oneOff.data(), oneOff.size()));
    REQUIRE_FALSE(probe.containsPolyline(twoOff.data(), twoOff.size()));
    // Two vertices inside, the straight segment between them out: the samples between count.
    const std::vector<Vec3f> arc{Vec3f(0.f), Vec3f(5.f, 3.f, 0.f), Vec3f(10.f, 0.f, 0.f)};
    const std::vector<Vec3f> chord{Vec3f(0.f), Vec3f(10.f, 0.f, 0.f)};
    REQUIRE_FALSE(probe.containsPolyline(arc.data(), arc.size()));
    REQUIRE(probe.containsPolyline(chord.data(), chord.size()));

    // containsChanged(): only the first vertex and the segments that differ from the reference
    // are tested. A path out of the volume that the reference shares is not the change's doing.
    const std::vector<Vec3f> outAndBack{Vec3f(0.f), Vec3f(3.f, 0.f, 0.f), Vec3f(3.f, 4.f, 0.f), Vec3f(6.f, 0.f, 0.f), Vec3f(10.f, 0.f, 0.f)};
    std::vector<Vec3f> tipMoved = outAndBack;
    tipMoved.back() = Vec3f(10.f, 0.5f, 0.f);  // inside (the dilation)
    REQUIRE_FALSE(probe.containsPolyline(tipMoved.data(), tipMoved.size()));
    REQUIRE(probe.containsChanged(tipMoved.data(), outAndBack.data(), tipMoved.size()));
    REQUIRE(probe.containsChanged(outAndBack.data(), outAndBack.data(), outAndBack.size()));
    std::vector<Vec3f> tipOut = outAndBack;
    tipOut.back() = Vec3f(10.f, 2.f, 0.f);  // the changed segment leaves the volume
    REQUIRE_FALSE(probe.containsChanged(tipOut.data(), outAndBack.data(), tipOut.size()));
    // Against a straight reference, every segment of the detour differs and is tested.
    std::vector<Vec3f> straight{Vec3f(0.f), Vec3f(3.f, 0.f, 0.f), Vec3f(4.5f, 0.f, 0.f), Vec3f(6.f, 0.f, 0.f), Vec3f(10.f, 0.f, 0.f)};
    REQUIRE_FALSE(probe.containsChanged(outAndBack.data(), straight.data(), outAndBack.size()));
    REQUIRE(probe.containsChanged(straight.data(), outAndBack.data(), straight.size()));
    // A first vertex that differs is tested on its own.
    std::vector<Vec3f> rootOut = straight, rootIn = straight;
    rootOut.front() = Vec3f(0.f, 2.f, 0.f);
    rootIn.front() = Vec3f(0.f, 0.5f, 0.f);
    const std::vector<Vec3f> root{Vec3f(0.f, 2.f, 0.f)};
    REQUIRE_FALSE(probe.containsChanged(root.data(), straight.data(), 1));
    REQUIRE(probe.containsChanged(rootIn.data(), straight.data(), 1));
    REQUIRE_FALSE(probe.containsChanged(rootOut.data(), straight.data(), rootOut.size()));
}

TEST_CASE("retraceConsistent: a strand whose retrace would leave the hair volume is left as it was", "[field]")
{
    // A strand through a sphere head that must be kept outside: the retrace slides around the
    // sphere, far from the strand's own voxels, so the strand is left as it was, its vertices
    // only moved out of the head.
    StrandSet s;
    s.addStrand(line(Vec3f(-10.f, 0.3f, 0.f), Vec3f(1.f, 0.f, 0.f), 20.f, 41));
    FieldParams fp;
    fp.voxelSize = 0.5;
    const TangentField f = estimateTangentField(s, fp);
    const HeadObstacle head = HeadObstacle::sphere(Vec3d(0.0), 3.0, HeadPolicy::KeepOutside);
    ConsistencyStats stats;
    const StrandSet out = retraceConsistent(s, f, ConsistencyParams{}, head, &stats);
    REQUIRE(stats.reverted == 1);
    for (std::size_t j = 0; j < s.size(0); ++j) {
        const Vec3d in(s.data(0)[j]), o(out.data(0)[j]);
        CAPTURE(j, in, o);
        if (in.length() >= 3.0) {
            REQUIRE(o == in);
        } else {
            REQUIRE(o.length() == Approx(3.0).epsilon(1e-3));  // moved out onto the surface
            REQUIRE((o / o.length() - in / in.length()).length() < 1e-5);  // along its own radius
        }
    }
}

TEST_CASE("retraceConsistent: where the strand's own direction wins, the retrace is the input to the last bit", "[field]")
{
    // A straight bundle and one strand in it that follows it for 5 units, then kinks
    // off at 30 degrees: every sub-step of the bundle keeps its own direction, so the retrace,
    // exact in exact arithmetic, must give the input bit for bit; so must the kinked strand up to
    // its kink (its correction starts there). Sub-steps are counted as the trace takes them.
    // The bundle runs obliquely, so that its points are not exact in binary and the sub-steps
    // round differently from the input's vertices.
    const Vec3f dir = Vec3f(1.f, 0.37f, 0.21f).unit();
    const Vec3f u = dir.cross(Vec3f(0.f, 0.f, 1.f)).unit(), v = dir.cross(u);
    const Vec3f origin(0.3f, -1.7f, 2.9f);
    StrandSet s;
    for (int j = 0; j < 12; ++j) {
        for (int k = 0; k < 12; ++k) s.addStrand(line(origin + u * (0.17f * float(j)) + v * (0.17f * float(k)), dir, 10.f, 41));
    }
    const std::size_t inliers = s.numStrands();
    const Vec3f axis = origin + (u + v) * (0.17f * 5.5f);  // the bundle's axis passes here, along dir
    std::vector<Vec3f> kinked = line(axis + u * 0.03f, dir, 5.f, 21);
    const float a = float(30.0 * M_PI / 180.0);
    for (std::size_t j = 1; j <= 20; ++j) kinked.push_back(kinked[20] + (dir * std::cos(a) + u * std::sin(a)) * (0.25f * float(j)));
    s.addStrand(kinked);
    FieldParams fp;
    fp.voxelSize = 0.5;
    const TangentField f = estimateTangentField(s, fp);
    ConsistencyParams cp;
    ConsistencyStats stats;
    const StrandSet out = retraceConsistent(s, f, cp, HeadObstacle::none(), &stats);
    const double step = resolveStepLength(cp.step, fp.voxelSize, "test");  // the default: half a voxel
    std::size_t steps = 0;
    for (std::size_t i = 0; i < s.numStrands(); ++i) {
        for (std::size_t j = 0; j + 1 < s.size(i); ++j) {
            const double len = (Vec3d(s.data(i)[j + 1]) - Vec3d(s.data(i)[j])).length();  // as the trace measures it
            if (len > 0.0) steps += std::max<std::size_t>(1, std::size_t(std::ceil(len / step)));
        }
    }
    REQUIRE(stats.steps == steps);
    REQUIRE(stats.corrected == 1);
    std::size_t exact = 0;
    for (std::size_t i = 0; i < inliers; ++i) {
        exact += std::equal(s.data(i), s.data(i) + s.size(i), out.data(i)) ? 1 : 0;
    }
    REQUIRE(exact == inliers);
    const std::size_t k = inliers;
    for (std::size_t j = 0; j <= 20; ++j) {
        CAPTURE(j);
        REQUIRE(out.data(k)[j] == s.data(k)[j]);
    }
    // ...and the kink is pulled back into the bundle's flow: the tip comes closer to the axis.
    auto offAxis = [&](const Vec3f& p) { const Vec3f q = p - axis; return (q - dir * q.dot(dir)).length(); };
    REQUIRE(offAxis(out.tip(k)) < 0.5f * offAxis(s.tip(k)));
}

TEST_CASE("refineStrands: two wisps crossing in an X stay an X", "[field]")
{
    // Two wisps of 49 strands each, crossing at 60 degrees at the origin.
    StrandSet s;
    const float a = 30.f * float(M_PI) / 180.f;
    for (int w = 0; w < 2; ++w) {
        const Vec3f dir(std::cos(a), w == 0 ? std::sin(a) : -std::sin(a), 0.f);
        const Vec3f side(-dir.y(), dir.x(), 0.f);
        for (int j = 0; j < 7; ++j) {
            for (int k = 0; k < 7; ++k) {
                const Vec3f root = dir * -5.f + side * (0.15f * float(j - 3)) + Vec3f(0.f, 0.f, 0.15f * float(k - 3));
                s.addStrand(line(root, dir, 10.f, 41));
            }
        }
    }
    RefineParams rp;
    rp.field.voxelSize = 0.4;
    rp.levels = 2;
    rp.head = HeadObstacle::none();
    const RefineResult r = refineStrands(s, rp);
    std::size_t swapped = 0;
    double worst = 0.0;
    for (std::size_t i = 0; i < s.numStrands(); ++i) {
        if ((s.tip(i).y() > 0.f) != (r.strands.tip(i).y() > 0.f)) ++swapped;
        worst = std::max(worst, maxDisplacement(s, r.strands, i));
    }
    CAPTURE(worst);
    REQUIRE(swapped == 0);
    REQUIRE(worst < 0.1 * 0.4);

    // The paper's rule merges the wisps where they cross: a single-valued field holds one direction.
    rp.mode = RefineMode::Field;
    const RefineResult paper = refineStrands(s, rp);
    double paperWorst = 0.0;
    for (std::size_t i = 0; i < s.numStrands(); ++i) paperWorst = std::max(paperWorst, maxDisplacement(s, paper.strands, i));
    CAPTURE(paperWorst);
    REQUIRE(paperWorst > 10.0 * worst);
}

TEST_CASE("refineStrands: a strand pointed into a sphere head is kept outside it", "[field]")
{
    // Strands rooted on top of a unit sphere and heading down through it, in a bundle that
    // flows over the sphere (so the field itself would carry them in).
    StrandSet s;
    for (int j = 0; j < 5; ++j) {
        const float x = 0.05f * float(j - 2);
        s.addStrand(line(Vec3f(x, 1.02f, 0.f), Vec3f(0.3f, -1.f, 0.f), 2.f, 21));
    }
    RefineParams rp;
    rp.field.voxelSize = 0.1;
    rp.head = HeadObstacle::sphere(Vec3d(0.0), 1.0);
    rp.measure = true;
    const RefineResult r = refineStrands(s, rp);
    for (std::size_t i = 0; i < r.strands.numStrands(); ++i) {
        for (std::size_t j = 0; j < r.strands.size(i); ++j) {
            CAPTURE(i, j);
            REQUIRE(r.strands.data(i)[j].length() >= 1.f);
        }
    }
    const RefineMeasures& m = r.levels.front().measures;
    REQUIRE(m.insideHeadBefore > 0);
    REQUIRE(m.insideHeadAfter == 0);
    REQUIRE(r.levels.front().consistency.pushedOut > 0);

    // A head that was only guessed (NoDeeper) never pushes a vertex deeper than the input had it.
    rp.head = HeadObstacle::sphere(Vec3d(0.0), 1.0, HeadPolicy::NoDeeper);
    const RefineResult guessed = refineStrands(s, rp);
    REQUIRE(guessed.levels.front().measures.insideHeadAfter <= m.insideHeadBefore);
}

TEST_CASE("refineStrands: a helix bundle keeps its helix through 3 levels", "[field]")
{
    StrandSet s;
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> jitter(-0.3f, 0.3f);
    for (int j = 0; j < 36; ++j) {
        std::vector<Vec3f> h = test::helix(1.0, 0.3, 6.0 * M_PI, 121);
        const Vec3f offset(jitter(rng), jitter(rng), 0.f);
        for (Vec3f& p : h) p += offset;
        s.addStrand(h);
    }
    const double kappa = 1.0 / (1.0 + 0.09);  // r / (r² + c²)
    RefineParams rp;
    rp.levels = 3;
    rp.head = HeadObstacle::none();
    rp.field.voxelSize = 0.15;
    rp.measure = true;
    const RefineResult r = refineStrands(s, rp);
    std::vector<float> curv;
    double mean = 0.0;
    std::size_t n = 0;
    for (std::size_t i = 0; i < r.strands.numStrands(); ++i) {
        curv.resize(r.strands.size(i));
        curvatureProfile(r.strands.data(i), curv.size(), curv.data());
        for (std::size_t j = 1; j + 1 < curv.size(); ++j, ++n) mean += curv[j];
    }
    mean /= double(n);
    CAPTURE(mean, kappa);
    REQUIRE(mean == Approx(kappa).epsilon(0.1));
    REQUIRE(r.levels.front().measures.curvatureKept8 > 0.9);
}

TEST_CASE("refineStrands: identical for 1 and 2 threads", "[field]")
{
    StrandSet s = bundle(12, 1.2f, 6.f, 25);
    std::mt19937 rng(3);
    std::normal_distribution<float> noise(0.f, 0.05f);
    for (Vec3f& p : s.positions) p += Vec3f(0.f, noise(rng), noise(rng));
    for (RefineMode mode : {RefineMode::Consistent, RefineMode::Field}) {
        RefineParams rp;
        rp.mode = mode;
        rp.levels = 2;
        rp.field.voxelSize = 0.3;
        rp.measure = true;
        const RefineResult one = refineStrands(s, rp, /*threaded=*/false);
        const RefineResult two = refineStrands(s, rp, /*threaded=*/true);
        REQUIRE(one.strands.positions == two.strands.positions);
        REQUIRE(one.levels.front().measures.displacementMean == two.levels.front().measures.displacementMean);
    }
}

TEST_CASE("refineStrands: a hairstyle given up is refined in its own storage, bit for bit as a kept one", "[field]")
{
    // A noisy bundle, three strands heading off it (corrected), one into a sphere head (pushed out).
    StrandSet s = bundle(12, 1.2f, 6.f, 25);
    std::mt19937 rng(5);
    std::normal_distribution<float> noise(0.f, 0.05f);
    for (Vec3f& p : s.positions) p += Vec3f(0.f, noise(rng), noise(rng));
    for (int k = 0; k < 3; ++k) {
        const float a = (25.f + 5.f * float(k)) * float(M_PI) / 180.f;
        s.addStrand(line(Vec3f(0.f, 0.3f + 0.3f * float(k), 0.6f), Vec3f(std::cos(a), std::sin(a), 0.f), 6.f, 25));
    }
    s.addStrand(line(Vec3f(0.f, 0.6f, 0.6f), Vec3f(1.f, -1.f, 0.f), 3.f, 13));
    for (int levels : {1, 3}) {
        for (Integrator integ : {Integrator::Euler, Integrator::RK2}) {
            CAPTURE(levels, integratorName(integ));
            RefineParams rp;
            rp.levels = levels;
            rp.field.voxelSize = 0.3;
            rp.head = HeadObstacle::sphere(Vec3d(2.0, -2.5, 0.6), 2.6, HeadPolicy::KeepOutside);
            rp.setStep(0.0, integ);
            const RefineResult kept = refineStrands(s, rp);
            StrandSet given = s;
            const Vec3f* storage = given.positions.data();
            const RefineResult r = refineStrands(std::move(given), rp);
            REQUIRE(r.strands.positions.data() == storage);  // no second copy of the positions
            REQUIRE(r.strands.offsets == kept.strands.offsets);
            REQUIRE(r.strands.positions == kept.strands.positions);
            REQUIRE(kept.strands.positions != s.positions);
            std::size_t corrected = 0, pushed = 0;
            for (std::size_t l = 0; l < std::size_t(levels); ++l) {
                const ConsistencyStats& a = r.levels[l].consistency;
                const ConsistencyStats& b = kept.levels[l].consistency;
                REQUIRE((a.corrected == b.corrected && a.steps == b.steps && a.fieldSteps == b.fieldSteps && a.pushedOut == b.pushedOut &&
                         a.heldIn == b.heldIn && a.reverted == b.reverted && a.noFieldSteps == b.noFieldSteps));
                corrected += b.corrected;
                pushed += b.pushedOut;
            }
            if (levels == 1) {  // the paths taken: corrections and pushes out of the head
                REQUIRE(corrected > 0);
                REQUIRE(pushed > 0);
            }
            // The report's estimate is estimateRefineMemory()'s: the leaves counted exactly (level 0's
            // are the input field's own, the others walked).
            const RefineMemory m = estimateRefineMemory(s, rp);
            REQUIRE(r.memory.bytes == m.bytes);
            REQUIRE(kept.memory.bytes == m.bytes);
            REQUIRE(r.memory.footprints.size() == std::size_t(levels));
            for (std::size_t l = 0; l < std::size_t(levels); ++l) REQUIRE(r.memory.footprints[l].leaves == m.footprints[l].leaves);
        }
    }
    // With the measures, the input is needed to the end: refined from a copy, the same again.
    RefineParams rp;
    rp.field.voxelSize = 0.3;
    rp.measure = true;
    const RefineResult kept = refineStrands(s, rp);
    StrandSet given = s;
    const RefineResult r = refineStrands(std::move(given), rp);
    REQUIRE(r.strands.positions == kept.strands.positions);
    REQUIRE(r.levels.front().measures.displacementMean == kept.levels.front().measures.displacementMean);
    REQUIRE(r.levels.front().measures.displacementMean > 0.0);
}

TEST_CASE("refineStrands: bad parameters are refused, naming them", "[field]")
{
    const StrandSet s = bundle(3, 1.f, 2.f, 5);
    RefineParams rp;
    rp.levels = 0;
    REQUIRE_THROWS_WITH(refineStrands(s, rp), Contains("levels 0: must be between 1 and 8"));
    rp.levels = 1;
    rp.consistency.zFull = 1.0;
    REQUIRE_THROWS_WITH(refineStrands(s, rp), Contains("outlier_full"));
    REQUIRE_THROWS_WITH(refineStrands(StrandSet(), RefineParams{}), Contains("no strands"));
    REQUIRE_THROWS_AS(HeadObstacle::sphere(Vec3d(0.0), -1.0), ValueError);
}

TEST_CASE("suggestVoxelSize: three root spacings, within the head's scale", "[field]")
{
    // Roots 0.1 apart on a plane: three spacings.
    const StrandSet s = bundle(20, 2.f, 10.f, 11);
    REQUIRE(suggestVoxelSize(s) == Approx(0.3).epsilon(1e-5));
}

TEST_CASE("refineStrands: the shared hairstyles keep their shape at the defaults", "[field][data]")
{
    VDBHAIR_REQUIRE_SHARED_DATA();
    const std::string dir = test::sharedData() + "/hair/";
    for (const char* file : {"usc_data/harolongo.data", "tressfx/ascii_v2/hair_tail_16_guide.tfx", "ply/Curly_100.ply"}) {
        CAPTURE(file);
        const StrandSet s = readStrands(dir + file);
        RefineParams rp;
        rp.measure = true;
        const RefineResult r = refineStrands(s, rp);
        const RefineMeasures& m = r.levels.front().measures;
        CAPTURE(r.voxelSize, m.leftVolume, m.curvatureKept8, m.displacementMean, m.coherenceBefore, m.coherenceAfter);
        REQUIRE(double(m.fullLength) >= 0.99 * double(s.numStrands()));
        REQUIRE(m.leftVolume == 0);
        REQUIRE(m.insideHeadAfter <= m.insideHeadBefore);
        REQUIRE(m.curvatureKept8 >= 0.8);
        REQUIRE(m.displacementMean < 1.0);
        REQUIRE(m.coherenceAfter >= m.coherenceBefore);
        REQUIRE(r.strands.offsets == s.offsets);
    }
}

TEST_CASE("refineStrands: a refinement whose memory estimate exceeds maxMemory is refused up front", "[field]")
{
    const StrandSet s = bundle(6, 2.f, 10.f, 21);
    RefineParams p;
    p.field.voxelSize = 0.5;
    p.levels = 2;
    const RefineMemory m = estimateRefineMemory(s, p);
    REQUIRE(m.footprints.size() == 2);
    // Each level's leaves are the leaves of the field refineStrands() estimates at that level.
    const RefineResult r = refineStrands(s, p);
    for (std::size_t l = 0; l < 2; ++l) {
        CAPTURE(l);
        CHECK(m.footprints[l].leaves == r.fields[l].tangent->tree().leafCount());
    }
    CHECK(r.memory.bytes == m.bytes);
    CHECK(m.bytes > estimatePeakBytes(m.footprints, MemoryUse::Field));  // a refinement holds more than its fields
    p.field.maxMemory = m.bytes - 1;
    REQUIRE_THROWS_AS(refineStrands(s, p), LimitError);
    REQUIRE_THROWS_WITH(refineStrands(s, p), Contains("refineStrands: needs about ") && Contains("(36 strands, 756 vertices, ") &&
                                                 Contains(" leaves in 2 level(s) from voxel size 0.500000), more than the ") &&
                                                 Contains("of max_memory; a request whose estimate exceeds the memory it may use is refused"));
    p.field.maxMemory = m.bytes;
    CHECK_NOTHROW(refineStrands(s, p));
}
