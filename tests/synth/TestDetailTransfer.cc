#include "SynthTestUtil.h"

#include <vdbhair/synth/Clustering.h>
#include <vdbhair/strands/Measures.h>
#include <vdbhair/synth/DetailTransfer.h>
#include <vdbhair/synth/impl/BalancedMatch.h>
#include <vdbhair/Random.h>

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <tuple>

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

TEST_CASE("balancedMatch: the same pairs, in the same order, as sorting every pair and scanning", "[synth]")
{
    // The oracle: every (distance², strand, member) pair sorted, then a strand not yet served
    // takes a member with room. Distances from a few values (many ties), caps below, at and above
    // the even share, one member and one strand.
    Rng rng(7, 0xba1u, 0);
    int refusals = 0;
    for (int trial = 0; trial < 300; ++trial) {
        const std::size_t strands = 1 + std::size_t(rng.uniform() * 12), members = 1 + std::size_t(rng.uniform() * 12);
        const double cap = double(1 + int(rng.uniform() * 3));
        std::vector<detail::MatchCandidate> cand(strands * members);
        std::vector<std::uint32_t> nearest(strands, 0);
        std::vector<std::tuple<double, std::uint32_t, std::uint32_t>> pairs;
        for (std::size_t a = 0; a < strands; ++a)
            for (std::size_t k = 0; k < members; ++k) {
                const double d = trial % 2 ? double(int(rng.uniform() * 4)) : rng.uniform();
                cand[a * members + k] = {d, std::uint32_t(k)};
                pairs.emplace_back(d, std::uint32_t(a), std::uint32_t(k));
                if (d < cand[a * members + nearest[a]].first) nearest[a] = std::uint32_t(k);
            }
        std::sort(pairs.begin(), pairs.end());
        std::vector<std::pair<std::uint32_t, std::uint32_t>> expected, got;
        std::vector<double> used(members, 0.0);
        std::vector<std::uint8_t> done(strands, 0);
        for (const auto& [d, a, k] : pairs) {
            if (done[a] || used[k] + 1.0 > cap) continue;
            done[a] = 1;
            used[k] += 1.0;
            expected.emplace_back(a, k);
        }
        detail::balancedMatch(cand, strands, members, nearest, cap, [&](std::uint32_t a, std::uint32_t k) { got.emplace_back(a, k); });
        CAPTURE(trial, strands, members, cap);
        REQUIRE(got == expected);
        for (const auto& [a, k] : got) refusals += k != nearest[a];
    }
    CHECK(refusals > 100);  // the heaps were exercised, not only the nearest members
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

TEST_CASE("transferDetail: edges give wisps transferred onto their own centres back", "[synth]")
{
    // Several wisps of different sizes (balanced matching must still pair each with itself), every
    // strand laid onto its own centre: the same carriers, frames and arcs, so the strand itself.
    const StrandSet hair = test::wispHairstyle(600, 6, nullptr, 32, 0.05);
    const StrandSamples strands = sampleStrands(hair, unitMap(), 32);
    ClusterParams params;
    const Clustering c = clusterSamples(strands, unitMap(), 6, false, params);
    REQUIRE(c.centers.count() == 6);
    const TransferSource src{&strands, &c.centers, &c.label};
    for (bool threaded : {true, false})
        for (DetailScale scale : {DetailScale::ArcLength, DetailScale::Strand, DetailScale::Index}) {
            TransferStats stats;
            const StrandSamples out = transferDetail(src, c.centers, strands.roots, unitMap(), 16, nullptr, &stats, DetailBlend::Edges,
                                                     threaded, nullptr, &c.label, scale);
            REQUIRE(out.count() == strands.count());
            CHECK(stats.distinctSources == 6);
            double worst = 0.0;  // of the strand's length (head radii: the unit sphere)
            for (std::size_t s = 0; s < out.count(); ++s)
                for (std::size_t k = 0; k < strands.dim(); ++k)
                    worst = std::max(worst, double(std::abs(out.row(s)[k] - strands.row(s)[k])) / double(strands.lengths[s]));
            CAPTURE(detailScaleName(scale), threaded);
            CHECK(worst < 1e-4);
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
    const StrandSamples out = transferDetail(src, outC, roots, unitMap(), 16, nullptr, nullptr, DetailBlend::RootFrame);
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

namespace {

/// Turning per length of a polyline: the sum of the angles between successive edges over its length.
double polylineTurningPerLength(const std::vector<Vec3f>& p)
{
    double turn = 0.0, len = 0.0;
    for (std::size_t k = 1; k < p.size(); ++k) {
        len += (Vec3d(p[k]) - Vec3d(p[k - 1])).length();
        if (k + 1 < p.size()) {
            const Vec3d a = (Vec3d(p[k]) - Vec3d(p[k - 1])).unitSafe(), b = (Vec3d(p[k + 1]) - Vec3d(p[k])).unitSafe();
            turn += std::acos(std::clamp(a.dot(b), -1.0, 1.0));
        }
    }
    return turn / len;
}

/// One strand of @a n vertices at the top of the unit head (root (0, 1, 0), growing along +y),
/// sampled on the unit map.
StrandSamples oneStrand(const std::vector<Vec3f>& p, int n)
{
    StrandSet s;
    s.addStrand(p);
    return sampleStrands(s, unitMap(), n);
}

/// A helix of radius @a r about the y axis from the root (0, 1, 0), @a c of rise per radian, @a turns turns.
std::vector<Vec3f> helix(double r, double c, double turns, int n)
{
    std::vector<Vec3f> p;
    for (int k = 0; k < n; ++k) {
        const double a = 2.0 * M_PI * turns * double(k) / double(n - 1);
        p.emplace_back(float(r * (std::cos(a) - 1.0)), float(1.0 + c * a), float(r * std::sin(a)));
    }
    return p;
}

/// A straight centre of @a length along y from the root (0, 1, 0), @a n vertices.
std::vector<Vec3f> line(double length, int n)
{
    std::vector<Vec3f> p;
    for (int k = 0; k < n; ++k) p.emplace_back(0.0f, float(1.0 + length * double(k) / double(n - 1)), 0.0f);
    return p;
}

/// The output of laying the one-strand cluster (@a strand about @a centre) onto @a outCentre, in world units.
std::vector<Vec3f> layOnto(const StrandSamples& strand, const StrandSamples& centre, const StrandSamples& outCentre, DetailScale scale,
                           int outVertices, bool threaded = true)
{
    const std::vector<std::uint32_t> label{0};
    const TransferSource src{&strand, &centre, &label};
    const StrandSamples out = transferDetail(src, outCentre, outCentre.roots, unitMap(), 16, nullptr, nullptr, DetailBlend::Edges,
                                             threaded, nullptr, nullptr, scale, outVertices);
    std::vector<Vec3f> w(std::size_t(out.vertices));
    sampleToWorld(out.row(0), out.vertices, out.roots[0], out.frames[0], 1.0, w.data());
    return w;
}

} // namespace

TEST_CASE("transferDetail: edges keep a helix's turning per length on a longer straight centre and on a quarter circle", "[synth]")
{
    // A helix of radius r = 0.02 and rise c = 0.01 per radian: curvature r / (r² + c²) = 40 per
    // head radius (STYLE.md's oracle), six turns, 0.84 radii of strand along 0.38 of axis.
    const double r = 0.02, c = 0.01, turns = 6.0, kappa = r / (r * r + c * c);
    const int ns = 128;
    const StrandSamples strand = oneStrand(helix(r, c, turns, 1024), ns);
    const double axis = c * 2.0 * M_PI * turns;
    const StrandSamples centre = oneStrand(line(axis, 64), ns);
    std::vector<Vec3f> in(ns);
    sampleToWorld(strand.row(0), ns, strand.roots[0], strand.frames[0], 1.0, in.data());
    const double tIn = polylineTurningPerLength(in);
    INFO("the helix sampled: turning per length " << tIn << " against its curvature " << kappa);
    REQUIRE(tIn == Approx(kappa).epsilon(0.03));

    SECTION("three times as long, straight: the loop repeats, the strand stays on the centre")
    {
        const StrandSamples longCentre = oneStrand(line(3.0 * axis, 64), ns);
        for (bool threaded : {true, false}) {
            const std::vector<Vec3f> out = layOnto(strand, centre, longCentre, DetailScale::ArcLength, 3 * ns, threaded);
            const double tOut = polylineTurningPerLength(out);
            const Vec3d end(out.back());
            INFO("turning per length " << tOut << "; end " << end);
            CHECK(tOut == Approx(tIn).epsilon(0.03));
            // Ending on the axis at three times the helix's height (within the helix's diameter).
            CHECK(std::hypot(end.x() + r, end.z()) < 2.5 * r);
            CHECK(end.y() == Approx(1.0 + 3.0 * axis).margin(2.5 * r));
        }
        // Laid vertex by vertex, the same edges stretch three times: a third of the turning.
        const double tIndex = polylineTurningPerLength(layOnto(strand, centre, longCentre, DetailScale::Index, 3 * ns));
        CHECK(tIndex == Approx(tIn / 3.0).epsilon(0.05));
        // At the strand's own length: the helix as it was, up to where its carrier (its low-pass,
        // both ends kept) leans off the axis near the ends, about a helix radius.
        const std::vector<Vec3f> own = layOnto(strand, centre, longCentre, DetailScale::Strand, ns);
        double worst = 0.0;
        for (int k = 0; k < ns; ++k) worst = std::max(worst, (Vec3d(own[std::size_t(k)]) - Vec3d(in[std::size_t(k)])).length());
        INFO("own length: worst " << worst);
        CHECK(worst < 2.0 * r);
    }
    SECTION("a quarter circle twice as long: the helix winds round the bend and ends at its end")
    {
        const double length = 2.0 * axis, radius = length / (0.5 * M_PI);
        std::vector<Vec3f> arc;
        for (int k = 0; k < 256; ++k) {
            const double a = 0.5 * M_PI * double(k) / 255.0;
            arc.emplace_back(float(radius * (1.0 - std::cos(a))), float(1.0 + radius * std::sin(a)), 0.0f);
        }
        const StrandSamples bent = oneStrand(arc, ns);
        const std::vector<Vec3f> out = layOnto(strand, centre, bent, DetailScale::ArcLength, 2 * ns);
        const double tOut = polylineTurningPerLength(out);
        const Vec3d end(out.back()), want(arc.back());
        INFO("turning per length " << tOut << "; end " << end << " against the centre's " << want);
        CHECK(tOut == Approx(tIn).epsilon(0.03));
        CHECK((end - want).length() < 3.0 * r);
    }
}

TEST_CASE("transferDetail: a strand shorter than its curl's period continues as its helix on a longer centre", "[synth]")
{
    // Three quarters of a turn of the helix of radius r = 0.02, rise c = 0.01 per radian (a C:
    // its carrier holds the curl, its edges little of it): curvature 40 per head radius, its
    // edges at cos = c / (r² + c²)^½ to the axis.
    const double r = 0.02, c = 0.01, turns = 0.75, kappa = r / (r * r + c * c);
    const int ns = 64;
    const StrandSamples strand = oneStrand(helix(r, c, turns, 256), ns);
    const double axis = c * 2.0 * M_PI * turns;
    const StrandSamples centre = oneStrand(line(axis, 64), ns);
    // Eight times as long: seven of every eight parts of the output are continuation.
    const StrandSamples longCentre = oneStrand(line(8.0 * axis, 64), ns);
    for (bool threaded : {true, false}) {
        const std::vector<Vec3f> out = layOnto(strand, centre, longCentre, DetailScale::ArcLength, 16 * ns, threaded);
        const double tOut = polylineTurningPerLength(out);
        // Past the strand's first turn (the lean eased to the helix's), the distance from the
        // helix's axis, which the strand's carrier offsets by where its own end left it.
        double outside = 0.0, sum = 0.0, sum2 = 0.0;
        std::size_t count = 0;
        std::vector<Vec3d> tail;
        for (const Vec3f& p : out)
            if (p.y() > 1.0 + 4.0 * axis) tail.emplace_back(p);
        Vec3d mid(0.0);
        for (const Vec3d& p : tail) mid += Vec3d(p.x(), 0.0, p.z()) / double(tail.size());
        for (const Vec3d& p : tail) {
            const double d = std::hypot(p.x() - mid.x(), p.z() - mid.z());
            sum += d;
            sum2 += d * d;
            ++count;
            outside = std::max(outside, d);
        }
        const double meanRadius = sum / double(count), spread = std::sqrt(std::max(0.0, sum2 / double(count) - meanRadius * meanRadius));
        const Vec3d end(out.back());
        INFO("turning per length " << tOut << " against " << kappa << "; radius " << meanRadius << " +- " << spread << " (max " << outside
                                   << ") against " << r << "; end " << end);
        REQUIRE(count > 100);
        CHECK(tOut == Approx(kappa).epsilon(0.1));
        CHECK(meanRadius == Approx(r).epsilon(0.15));
        CHECK(spread < 0.15 * r);
        CHECK(end.y() == Approx(1.0 + 8.0 * axis).margin(2.5 * r));
    }
}

namespace {

/// Straight strands along the normal of the unit sphere, rooted in a small cap around @a at.
StrandSet radialStrands(const Vec3d& at, std::size_t count, double length, std::uint64_t seed)
{
    StrandSet out;
    Rng rng(seed, 0x9a1u, 0);
    const Vec3d c = at.unitSafe();
    for (std::size_t s = 0; s < count; ++s) {
        const Vec3d n = (c + Vec3d(rng.uniform() - 0.5, rng.uniform() - 0.5, rng.uniform() - 0.5) * 0.1).unitSafe();
        std::vector<Vec3f> p;
        for (int l = 0; l < 8; ++l) p.emplace_back(n * (1.0 + length * double(l) / 7.0));
        out.addStrand(p);
    }
    return out;
}

double meanLength(const StrandSamples& s, std::size_t from, std::size_t to)
{
    double sum = 0.0;
    for (std::size_t i = from; i < to; ++i) sum += s.lengths[i];
    return sum / double(to - from);
}

} // namespace

TEST_CASE("transferDetail: match place takes the wisps near an output wisp's place over those of its shape", "[synth]")
{
    // Input: short strands (0.3) around P, long ones (0.6) around Q, one wisp each. Output
    // centres: a long one at P and a short one at Q, and the output roots are the input's. By
    // shape each output wisp takes the input wisp of its length (the other place); with place
    // weight enough, the one at its own place, so each place keeps its lengths.
    const Vec3d P(0.6, 0.8, 0.0), Q(-0.6, 0.8, 0.0);
    StrandSet in = radialStrands(P, 100, 0.3, 1);
    in.append(radialStrands(Q, 100, 0.6, 2));
    const StrandSamples strands = sampleStrands(in, unitMap(), 16);
    ClusterParams params;
    const Clustering c = clusterSamples(strands, unitMap(), 2, false, params);
    REQUIRE(c.centers.count() == 2);
    StrandSet centres = radialStrands(P, 1, 0.6, 3);
    centres.append(radialStrands(Q, 1, 0.3, 4));
    const StrandSamples outC = sampleStrands(centres, unitMap(), 16);
    const TransferSource src{&strands, &c.centers, &c.label};
    for (double place : {0.0, 10.0})
        for (bool threaded : {true, false}) {
            DetailMatchParams match;
            match.place = place;
            const StrandSamples out = transferDetail(src, outC, strands.roots, unitMap(), 16, nullptr, nullptr, DetailBlend::Edges, threaded,
                                                     nullptr, nullptr, DetailScale::Strand, 0, match);
            REQUIRE(out.count() == 200);
            CAPTURE(place, threaded);
            // Strands 0-99 are rooted at P, 100-199 at Q.
            const double atP = meanLength(out, 0, 100), atQ = meanLength(out, 100, 200);
            CHECK(atP == Approx(place > 0.0 ? 0.3 : 0.6).epsilon(0.05));
            CHECK(atQ == Approx(place > 0.0 ? 0.6 : 0.3).epsilon(0.05));
        }
    DetailMatchParams bad;
    bad.place = -1.0;
    CHECK_THROWS_WITH(bad.validate("test"), Catch::Contains("match_place -1"));
}

TEST_CASE("transferDetail: with wisps matched by place, a strand whose offset the wisps' frames would turn up off the head keeps it against the scalp", "[synth]")
{
    // On the side of the unit head, 45 degrees up: the input wisp's centre runs around the head
    // (horizontally) and its strand runs the other way, so the strand's offset from its centre is
    // horizontal. The output centre at the same root runs down the slope instead. Turned with the
    // wisps' aligned tangents (Eq. 4), "behind the centre" becomes "up the slope" and the strand
    // would rise off the head by 0.7 of its length (Ruby's short hair: a tuft 29 units above the
    // head); neither the input strand nor the output centre rises, so with wisps matched by place
    // (synthesis) the offset is turned as the scalp's normal turns and stays horizontal. Matched
    // by shape (transfer), the wisps' frames carry it, as the paper's.
    const double h = std::sqrt(0.5), len = 0.4;
    const Vec3d root(h, h, 0.0), around(0.0, 0.0, 1.0), down(h, -h, 0.0);
    const auto straight = [&](const Vec3d& dir) {
        std::vector<Vec3f> p;
        for (int k = 0; k < 16; ++k) p.emplace_back(root + dir * (len * double(k) / 15.0));
        return oneStrand(p, 16);
    };
    const StrandSamples strand = straight(-around), centre = straight(around), outCentre = straight(down);
    const std::vector<std::uint32_t> label{0};
    const TransferSource src{&strand, &centre, &label};
    for (double place : {0.0, 1.0}) {
        CAPTURE(place);
        DetailMatchParams match;
        match.place = place;
        const StrandSamples out = transferDetail(src, outCentre, outCentre.roots, unitMap(), 16, nullptr, nullptr, DetailBlend::Edges,
                                                 true, nullptr, nullptr, DetailScale::Strand, 0, match);
        std::vector<Vec3f> w(std::size_t(out.vertices));
        sampleToWorld(out.row(0), out.vertices, out.roots[0], out.frames[0], 1.0, w.data());
        double rise = 0.0, length = 0.0;
        for (std::size_t k = 0; k < w.size(); ++k) {
            rise = std::max(rise, double(w[k].y()) - root.y());
            if (k) length += (Vec3d(w[k]) - Vec3d(w[k - 1])).length();
        }
        if (place > 0.0) CHECK(rise < 0.01 * len);
        else CHECK(rise > 0.5 * len);
        CHECK(length == Approx(len).epsilon(0.02));
    }
}
