#include "SynthTestUtil.h"

#include <vdbhair/synth/Clustering.h>
#include <vdbhair/synth/DetailTransfer.h>

#include <catch2/catch.hpp>

using namespace vdbhair;

namespace {
const ScalpMap& unitMap()
{
    static const ScalpMap map{ScalpSphere{}};
    return map;
}
} // namespace

TEST_CASE("alignedFrame: the tangent follows the strand's mean direction on the tangent plane", "[synth]")
{
    ScalpFrame f;  // identity at the top of the head
    std::vector<float> row;
    for (int l = 0; l < 8; ++l) {
        const float a = float(l) / 7.0f;
        row.insert(row.end(), {0.3f * a, a, -0.3f * a});  // leans towards +x, -z
    }
    const ScalpFrame g = alignedFrame(row.data(), 8, f);
    CHECK((g.t - Vec3d(1, 0, -1).unitSafe()).length() < 1e-6);
    CHECK((g.n - f.n).length() < 1e-12);
    CHECK((g.t.cross(g.n) - g.b).length() < 1e-9);
}

TEST_CASE("transferDetail: a cluster transferred onto its own centre is the cluster", "[synth]")
{
    // One wisp: its strands, its centre (the mean), every strand labelled 0.
    const StrandSet hair = test::wispHairstyle(300, 1, nullptr, 16, 0.05);
    const StrandSamples strands = sampleStrands(hair, unitMap(), 16);
    ClusterParams params;
    const Clustering c = clusterSamples(strands, unitMap(), 1, false, params);
    REQUIRE(c.centers.count() == 1);
    const TransferSource src{&strands, &c.centers, &c.label};
    std::vector<std::uint32_t> label;
    TransferStats stats;
    for (bool threaded : {true, false})
        for (DetailBlend blend : {DetailBlend::RootFrame, DetailBlend::Paper}) {
        const StrandSamples out = transferDetail(src, c.centers, strands.roots, unitMap(), 16, &label, &stats, blend, threaded);
        REQUIRE(out.count() == strands.count());
        CHECK(stats.clusters == 1);
        CHECK(stats.distinctSources == 1);
        double worst = 0.0;
        for (std::size_t i = 0; i < out.local.size(); ++i) worst = std::max(worst, double(std::abs(out.local[i] - strands.local[i])));
        CHECK(worst < 1e-5);
    }
}

TEST_CASE("transferDetail: detail follows a turned centre and new roots keep their root", "[synth]")
{
    // Input: one wavy wisp. Output: the same wisp's centre at the other side of the head (turned
    // by 90 degrees about y), new roots around it. Each output strand's offsets from its centre,
    // in the centre's frame, equal the matched input strand's (Eq. 7-8 with equal D_alpha, D_beta
    // frames up to the turn): so the output is the input turned, where roots match.
    const StrandSet hair = test::wispHairstyle(200, 1, nullptr, 16, 0.08);
    const StrandSamples strands = sampleStrands(hair, unitMap(), 16);
    ClusterParams params;
    const Clustering c = clusterSamples(strands, unitMap(), 1, false, params);
    // Turn the centre and the roots by 90 degrees about y.
    const auto turn = [](const Vec3d& p) { return Vec3d(p.z(), p.y(), -p.x()); };
    StrandSamples outC;
    outC.vertices = 16;
    {
        const Vec3d root = turn(c.centers.roots[0]);
        const Vec3d sc = unitMap().toScalp(root);
        const ScalpFrame rf = unitMap().frame(sc.x(), sc.y());
        // World centre turned, back into the new root frame.
        std::vector<Vec3f> w(16);
        sampleToWorld(c.centers.row(0), 16, c.centers.roots[0], c.centers.frames[0], 1.0, w.data());
        std::vector<float> row(48);
        for (int l = 0; l < 16; ++l) {
            const Vec3d q = rf.toLocal(turn(Vec3d(w[std::size_t(l)])) - root);
            row[3 * l] = float(q.x()); row[3 * l + 1] = float(q.y()); row[3 * l + 2] = float(q.z());
        }
        outC.push(row.data(), root, sc, rf, c.centers.lengths[0]);
    }
    std::vector<Vec3d> roots;
    for (const Vec3d& r : strands.roots) roots.push_back(turn(r));
    const TransferSource src{&strands, &c.centers, &c.label};
    const StrandSamples out = transferDetail(src, outC, roots, unitMap(), 16);
    REQUIRE(out.count() == roots.size());
    double worst = 0.0;
    for (std::size_t i = 0; i < out.count(); ++i) {
        std::vector<Vec3f> got(16), want(16);
        sampleToWorld(out.row(i), 16, out.roots[i], out.frames[i], 1.0, got.data());
        sampleToWorld(strands.row(i), 16, strands.roots[i], strands.frames[i], 1.0, want.data());
        CHECK((Vec3d(got[0]) - roots[i]).length() < 1e-5);
        for (int l = 0; l < 16; ++l) worst = std::max(worst, (Vec3d(got[std::size_t(l)]) - turn(Vec3d(want[std::size_t(l)]))).length());
    }
    // The scalp frames at turned roots are not exactly the turned frames (R takes +y to the
    // normal), so allow a small tolerance.
    CHECK(worst < 1e-3);
}
