#include "../TestUtil.h"

#include <vdbhair/Quantile.h>
#include <vdbhair/field/HeadObstacle.h>
#include <vdbhair/synth/StyleRegions.h>

#include <cmath>

using namespace vdbhair;

namespace {

/// A root on the unit sphere at @a elevation above the horizon and @a azimuth from +Z towards +X (degrees).
Vec3d rootAt(double elevationDeg, double azimuthDeg)
{
    const double e = elevationDeg * M_PI / 180.0, a = azimuthDeg * M_PI / 180.0;
    return Vec3d(std::cos(e) * std::sin(a), std::sin(e), std::cos(e) * std::cos(a));
}

void addLine(StrandSet& s, const Vec3d& root, const Vec3d& direction, double length, int vertices = 33)
{
    std::vector<Vec3f> pts;
    for (int k = 0; k < vertices; ++k) pts.emplace_back(root + direction * (length * double(k) / double(vertices - 1)));
    s.addStrand(pts);
}

} // namespace

TEST_CASE("quantile: linear between order statistics, as NumPy's default", "[core]")
{
    REQUIRE(quantile({}, 0.5) == 0.0);
    REQUIRE(quantile({5.0}, 0.9) == 5.0);
    REQUIRE(quantile({5.0, 1.0, 4.0, 2.0, 3.0}, 0.25) == 2.0);
    REQUIRE(quantile({5.0, 1.0, 4.0, 2.0, 3.0}, 0.5) == 3.0);
    REQUIRE(quantile({1.0, 2.0, 3.0, 4.0}, 0.5) == Approx(2.5));   // numpy.quantile([1,2,3,4], .5)
    REQUIRE(quantile({1.0, 2.0, 3.0, 4.0}, 0.9) == Approx(3.7));   // numpy.quantile([1,2,3,4], .9)
    REQUIRE(quantile({3.0, 1.0, 2.0}, 1.0) == 3.0);
}

TEST_CASE("measureStyleRegions: regions, front, lengths, lift, turning, curl and the head on a sphere", "[synth][regions]")
{
    StrandSet s;
    // Crown: 4 strands straight up from 70 degrees (they lift), length 0.5.
    for (int i = 0; i < 4; ++i) addLine(s, rootAt(70.0, 90.0 * i), Vec3d(0, 1, 0), 0.5);
    // The hairline below the crown, highest at the forehead (+Z) and lowest at the nape: short
    // strands rooted at 15 + 20 cos(azimuth) degrees, two in each region.
    for (int a : {30, 330, 75, 285, 150, 210}) addLine(s, rootAt(15.0 + 20.0 * std::cos(a * M_PI / 180.0), double(a)), Vec3d(0, -1, 0), 0.1);
    // Fringe: 2 strands from the forehead, hanging down, lengths 0.2 and 0.4.
    addLine(s, rootAt(35.0, -10.0), Vec3d(0, -1, 0), 0.2);
    addLine(s, rootAt(35.0, 10.0), Vec3d(0, -1, 0), 0.4);
    // Back: 5 strands hanging from behind (-Z), lengths 1..5: p25/p50/p75 = 2, 3, 4.
    for (int i = 0; i < 5; ++i) addLine(s, rootAt(10.0, 180.0 + 10.0 * (i - 2)), Vec3d(0, -1, 0), double(i + 1));
    // Sides: 2 strands, one of them waving across its length with amplitude A (8 waves) and one
    // going straight into the head through its centre (half its vertices inside).
    const double A = 0.005;  // gentle (slopes under 0.25): sampling by arc length barely weights the crossings
    {
        const Vec3d root = rootAt(0.0, 90.0);
        std::vector<Vec3f> pts;
        for (int k = 0; k < 257; ++k) {
            const double t = double(k) / 256.0;
            pts.emplace_back(root + Vec3d(0.0, -t, A * std::sin(2.0 * M_PI * 8.0 * t)));
        }
        s.addStrand(pts);
    }
    addLine(s, rootAt(0.0, -90.0), Vec3d(1, 0, 0), 1.0, 101);

    const RegionFrame frame = regionFrameFromRoots(s, Vec3d(0.0), Vec3d(0, 1, 0), 1.0);
    REQUIRE(frame.front.z() > 0.99);  // where the hairline is highest (within the 15-degree sectors)
    const HeadObstacle head = HeadObstacle::sphere(Vec3d(0.0), 1.0);
    const StyleRegions r = measureStyleRegions(s, frame, &head);
    const auto& crown = r.regions[int(StyleRegion::Crown)];
    const auto& fringe = r.regions[int(StyleRegion::Fringe)];
    const auto& back = r.regions[int(StyleRegion::Back)];
    const auto& sides = r.regions[int(StyleRegion::Sides)];
    REQUIRE(crown.strands == 4);
    REQUIRE(fringe.strands == 2 + 2);
    REQUIRE(back.strands == 5 + 2);
    REQUIRE(sides.strands == 2 + 2);
    REQUIRE(crown.share == Approx(4.0 / 19.0));
    REQUIRE(crown.lift == 1.0);
    REQUIRE(back.lift == 0.0);
    REQUIRE(fringe.lift == 0.0);
    // Back lengths 0.1, 0.1, 1, 2, 3, 4, 5: quartiles at positions 1.5, 3, 4.5 of the sorted seven.
    REQUIRE(back.lengthP25 == Approx(0.55));
    REQUIRE(back.lengthP50 == Approx(2.0));
    REQUIRE(back.lengthP75 == Approx(3.5));
    REQUIRE(fringe.lengthP50 == Approx(0.15));  // 0.1, 0.1, 0.2, 0.4
    REQUIRE(crown.turning == Approx(0.0).margin(1e-6));
    REQUIRE(crown.curlAmplitude == Approx(0.0).margin(1e-9));
    // The waving strand's amplitude: its RMS offset A / sqrt(2), over the two side strands long
    // enough for the figure (0.6 head radii: not the hairline's 0.1), the other straight; the waves
    // are far shorter than the smoothing, so it keeps all of it.
    REQUIRE(sides.curlAmplitude == Approx(A / std::sqrt(2.0) / 2.0).epsilon(0.03));
    REQUIRE(sides.turning > 1.0);
    // Inside the head: all but the root of the strand going through the centre, and of the two
    // hairline strands hanging straight down from above the equator (32 each); the crown's point up.
    REQUIRE(sides.insideHead == Approx((100.0 + 2 * 32.0) / (257.0 + 101.0 + 2 * 33.0)));
    REQUIRE(crown.insideHead == 0.0);
    // Without a head, no figure; the report sets example and output side by side.
    const StyleRegions noHead = measureStyleRegions(s, frame, nullptr, /*threaded=*/false);
    REQUIRE(noHead.regions[0].insideHead == -1.0);
    REQUIRE(noHead.regions[int(StyleRegion::Back)].lengthP50 == r.regions[int(StyleRegion::Back)].lengthP50);
    const nlohmann::json j = toJson(r, noHead);
    REQUIRE(j["crown"]["lift"]["example"] == 1.0);
    REQUIRE(j["sides"]["inside_head"]["output"].is_null());
    REQUIRE(j["back"]["strands"]["output"] == 7);
    REQUIRE(summaryLines(r, noHead).find("fringe") != std::string::npos);
}

TEST_CASE("measureStyleRegions: flow, the direction strands leave their roots in, down the head and around it", "[synth][regions]")
{
    RegionFrame frame;  // the unit sphere, up +Y, front +Z
    // Down the meridian and around the head (towards larger azimuth, +Z to +X) at a root.
    const auto down = [](double e, double a) {
        e *= M_PI / 180.0;
        a *= M_PI / 180.0;
        return Vec3d(std::sin(e) * std::sin(a), -std::cos(e), std::sin(e) * std::cos(a));
    };
    const auto around = [](double a) { return Vec3d(std::cos(a * M_PI / 180.0), 0.0, -std::sin(a * M_PI / 180.0)); };
    StrandSet s, mirrored;
    const auto both = [&](const Vec3d& root, const Vec3d& dir, const Vec3d& mirrorDir, double length) {
        addLine(s, root, dir, length);
        addLine(mirrored, root, mirrorDir, length);
    };
    // Fringe: swept around, one strand longer than the reach of the figure and one shorter (its tip).
    for (double a : {-20.0, 20.0}) both(rootAt(20.0, a), around(a), -1.0 * around(a), a < 0 ? 1.0 : 0.2);
    // Sides: falling straight down the head, lifted off it a little (the normal part is left out).
    for (double a : {90.0, -90.0}) {
        const Vec3d r = rootAt(10.0, a);
        both(r, (down(10.0, a) + 0.3 * r).unit(), (down(10.0, a) + 0.3 * r).unit(), 1.0);
    }
    // Back: half down, half around backwards: the mean of the unit directions.
    both(rootAt(0.0, 170.0), down(0.0, 170.0), down(0.0, 170.0), 1.0);
    both(rootAt(0.0, 190.0), -1.0 * around(190.0), around(190.0), 1.0);
    // Crown: straight out of the head, no direction in its tangent plane.
    both(rootAt(70.0, 0.0), rootAt(70.0, 0.0), rootAt(70.0, 0.0), 0.5);

    const StyleRegions r = measureStyleRegions(s, frame), m = measureStyleRegions(mirrored, frame, nullptr, false);
    const auto& fringe = r.regions[int(StyleRegion::Fringe)];
    const auto& sides = r.regions[int(StyleRegion::Sides)];
    const auto& back = r.regions[int(StyleRegion::Back)];
    const auto& crown = r.regions[int(StyleRegion::Crown)];
    REQUIRE(fringe.strands == 2);
    REQUIRE(fringe.flowDown == Approx(0.0).margin(1e-6));
    REQUIRE(fringe.flowAround == Approx(1.0));
    REQUIRE(sides.flowDown == Approx(1.0));
    REQUIRE(sides.flowAround == Approx(0.0).margin(1e-6));
    REQUIRE(back.flowDown == Approx(0.5));
    REQUIRE(back.flowAround == Approx(-0.5));
    REQUIRE(crown.strands == 1);
    REQUIRE(crown.flowDown == 0.0);
    REQUIRE(crown.flowAround == 0.0);
    // A fringe swept the other way: same lengths, lift and turning, opposite flow.
    const auto& fringeM = m.regions[int(StyleRegion::Fringe)];
    REQUIRE(fringeM.lengthP50 == Approx(fringe.lengthP50));
    REQUIRE(fringeM.flowAround == Approx(-1.0));
    const nlohmann::json j = toJson(r, m);
    REQUIRE(j["fringe"]["flow"]["example"][1] == Approx(1.0));
    REQUIRE(j["fringe"]["flow"]["output"][1] == Approx(-1.0));
    REQUIRE(j["fringe"]["flow_difference"] == Approx(2.0));
    REQUIRE(j["sides"]["flow_difference"] == Approx(0.0).margin(1e-6));
    REQUIRE(j["back"]["flow_difference"] == Approx(1.0));  // (0.5, -0.5) against (0.5, 0.5)
}

TEST_CASE("meanCurlAmplitude: hair lying on the head has no curl; a helix reads its radius", "[synth][regions]")
{
    // Strands along meridians of the unit sphere (on a head of radius 1), 1.8 head radii long from
    // 60 degrees above the equator: bent, not curled. The centre line of a Gaussian (the measure's
    // first form) cut across the bend and read 0.010 here.
    StrandSet lying;
    for (int a = 0; a < 8; ++a) {
        std::vector<Vec3f> pts;
        for (int k = 0; k < 91; ++k) pts.emplace_back(rootAt(60.0 - 1.8 * 180.0 / M_PI * double(k) / 90.0, 45.0 * a));
        lying.addStrand(pts);
    }
    CHECK(meanCurlAmplitude(lying, 1.0) < 0.0015);
    // The same strands on a head of radius 2 (twice as long in its radii, half as bent).
    CHECK(meanCurlAmplitude(lying, 0.5) < 0.0015);
    // Helices of radius 0.03 about straight axes, 2 head radii long: the RMS distance from the axis
    // is the radius; a period of 0.25 head radii keeps nearly all of it, one of a head radius (a
    // wave, not a curl) less than a third.
    const auto helices = [](double radius, double period) {
        StrandSet s;
        for (int a = 0; a < 4; ++a) {
            std::vector<Vec3f> pts;
            for (int k = 0; k < 401; ++k) {
                const double t = 2.0 * double(k) / 400.0, phase = 2.0 * M_PI * t / period + a;
                pts.emplace_back(Vec3d(3.0 * a + radius * std::cos(phase), -t, radius * std::sin(phase)));
            }
            s.addStrand(pts);
        }
        return s;
    };
    CHECK(meanCurlAmplitude(helices(0.03, 0.25), 1.0) == Approx(0.03).epsilon(0.1));
    CHECK(meanCurlAmplitude(helices(0.03, 1.0), 1.0) < 0.3 * 0.03);
    // Scales with the head: the same helices on a head of radius 2 read half as much.
    CHECK(meanCurlAmplitude(helices(0.03, 0.25), 2.0) == Approx(0.015).epsilon(0.1));
}
