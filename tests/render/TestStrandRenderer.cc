#include "../TestUtil.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/io/StrandIO.h>
#include <vdbhair/render/StrandRenderer.h>

#include <tbb/global_control.h>

using namespace vdbhair;

namespace {

/// Pixels that differ from the (white) background: where hair was drawn.
std::vector<bool> hairMask(const Image& im)
{
    std::vector<bool> m(std::size_t(im.width) * std::size_t(im.height));
    for (int y = 0; y < im.height; ++y) {
        for (int x = 0; x < im.width; ++x) {
            const Vec3f c = im.at(x, y);
            m[std::size_t(y) * std::size_t(im.width) + std::size_t(x)] = c.x() < 0.97f || c.y() < 0.97f || c.z() < 0.97f;
        }
    }
    return m;
}

struct PixelBox
{
    double x0 = 1e300, y0 = 1e300, x1 = -1e300, y1 = -1e300;
    void add(double x, double y) { x0 = std::min(x0, x); y0 = std::min(y0, y); x1 = std::max(x1, x); y1 = std::max(y1, y); }
};

/// The projected bounding box of @a s's vertices in the image of @a rp.
PixelBox projectedBox(const StrandSet& s, const RenderParams& rp, const BBox& frame)
{
    PixelBox b;
    for (const Vec3f& p : s.positions) {
        const Vec3d q = projectToImage(Vec3d(p), rp, frame);
        b.add(q.x(), q.y());
    }
    return b;
}

const View kViews[] = {View::Front, View::Side, View::Top, View::Back, View::ThreeQuarter};

} // namespace

TEST_CASE("renderStrands: a straight strand is drawn along its projection, end to end", "[render]")
{
    StrandSet s;
    s.addStrand(std::vector<Vec3f>{Vec3f(-1.f, -0.5f, 0.3f), Vec3f(1.f, 0.5f, -0.3f)});
    for (View view : kViews) {
        RenderParams rp;
        rp.view = view;
        rp.width = 200;
        rp.height = 160;
        const BBox frame = computeBBox(s);
        const Image im = renderStrands(s, rp);
        const std::vector<bool> m = hairMask(im);
        const Vec3d a = projectToImage(Vec3d(s.positions[0]), rp, frame), b = projectToImage(Vec3d(s.positions[1]), rp, frame);
        CAPTURE(viewName(view), a, b);
        // Every drawn pixel lies on the projected segment (within 1.5 pixels of it) ...
        std::size_t drawn = 0, off = 0;
        const Vec3d ab(b.x() - a.x(), b.y() - a.y(), 0.0);
        for (int y = 0; y < im.height; ++y) {
            for (int x = 0; x < im.width; ++x) {
                if (!m[std::size_t(y) * std::size_t(im.width) + std::size_t(x)]) continue;
                ++drawn;
                const Vec3d p(x + 0.5 - a.x(), y + 0.5 - a.y(), 0.0);
                const double t = std::min(1.0, std::max(0.0, p.dot(ab) / ab.lengthSqr()));
                off += (p - ab * t).length() > 1.5;
            }
        }
        CHECK(off == 0);
        // ... and the segment is covered: pixels near every point along it.
        const double len = ab.length();
        REQUIRE(len > 20.0);
        int gaps = 0;
        for (int k = 0; k <= int(len); ++k) {
            const double t = k / len;
            const int cx = int(a.x() + t * ab.x()), cy = int(a.y() + t * ab.y());
            bool near = false;
            for (int dy = -1; dy <= 1 && !near; ++dy)
                for (int dx = -1; dx <= 1 && !near; ++dx) {
                    const int x = cx + dx, y = cy + dy;
                    near = x >= 0 && y >= 0 && x < im.width && y < im.height && m[std::size_t(y) * std::size_t(im.width) + std::size_t(x)];
                }
            gaps += !near;
        }
        CHECK(gaps == 0);
        CHECK(drawn >= std::size_t(0.9 * len));
    }
}

TEST_CASE("renderStrands: up and facing axes turn the views (a z-up model matches its y-up copy)", "[render]")
{
    StrandSet yUp, zUp;
    for (int i = 0; i < 40; ++i) {
        std::vector<Vec3f> pts = test::helix(0.3 + 0.01 * i, 0.08, 9.0, 40, 0.2 * i);
        yUp.addStrand(pts);
        // (x, y, z) y-up facing +z is (x, -z, y) z-up facing -y (Blender's convention) ...
        for (Vec3f& p : pts) p = Vec3f(p.x(), -p.z(), p.y());
        zUp.addStrand(pts);
    }
    for (View view : kViews) {
        RenderParams a, b;
        a.view = b.view = view;
        a.width = a.height = b.width = b.height = 96;
        b.up = Vec3d(0, 0, 1);  // facing defaults to -y
        const Image ia = renderStrands(yUp, a), ib = renderStrands(zUp, b);
        float worst = 0.f;
        for (std::size_t k = 0; k < ia.rgb.size(); ++k) worst = std::max(worst, std::abs(ia.rgb[k] - ib.rgb[k]));
        CAPTURE(viewName(view));
        CHECK(worst < 0.02f);  // the same picture, up to float rounding of the rotated positions
    }
    RenderParams bad;
    bad.up = Vec3d(0, 0, 1);
    bad.facing = Vec3d(0, 0, -1);
    CHECK_THROWS_AS(renderStrands(yUp, bad), ValueError);
}

TEST_CASE("renderStrands: the same image for 1 and 2 threads and for repeated runs", "[render]")
{
    StrandSet s;
    for (int i = 0; i < 300; ++i) {
        const double phase = 0.37 * i;
        std::vector<Vec3f> pts = test::helix(0.3 + 0.002 * i, 0.05, 12.0, 60, phase);
        for (Vec3f& p : pts) p += Vec3f(0.01f * float(i % 17), 0.f, 0.01f * float(i / 17));
        s.addStrand(pts);
    }
    for (View view : kViews) {
        RenderParams rp;
        rp.view = view;
        rp.width = rp.height = 128;
        rp.colorBy = ColorBy::Curvature;
        Image one, two;
        {
            tbb::global_control c(tbb::global_control::max_allowed_parallelism, 1);
            one = renderStrands(s, rp);
        }
        {
            tbb::global_control c(tbb::global_control::max_allowed_parallelism, 2);
            two = renderStrands(s, rp);
        }
        CAPTURE(viewName(view));
        CHECK(one.rgb == two.rgb);
        CHECK(renderStrands(s, rp).rgb == two.rgb);
    }
}

TEST_CASE("renderStrands: real hairstyles cover their projected bounding box in every view, and each strand lands on its projection", "[render][data]")
{
    VDBHAIR_REQUIRE_SHARED_DATA();
    const std::string data = test::sharedData();
    // Straight, wavy, curly and short hair, in four formats.
    for (const char* file : {"hair/cyhair/straight.hair", "hair/usc_data/harolongo.data", "hair/ply/Curly_100.ply",
                             "hair/tressfx/binary_v4/Ratboy_mohawk.tfx"}) {
        const StrandSet s = readStrands(data + "/" + file);
        const BBox frame = computeBBox(s);
        const bool zUp = std::string(file).find("cyhair") != std::string::npos;  // Yuksel's models: z up, facing +y
        for (View view : kViews) {
            RenderParams rp;
            rp.view = view;
            if (zUp) {
                rp.up = Vec3d(0, 0, 1);
                rp.facing = Vec3d(0, 1, 0);
            }
            rp.width = rp.height = 192;
            rp.frame = frame;
            const Image im = renderStrands(s, rp);
            const std::vector<bool> m = hairMask(im);
            const PixelBox want = projectedBox(s, rp, frame);
            PixelBox got;
            std::size_t outside = 0, drawn = 0;
            for (int y = 0; y < im.height; ++y) {
                for (int x = 0; x < im.width; ++x) {
                    if (!m[std::size_t(y) * std::size_t(im.width) + std::size_t(x)]) continue;
                    ++drawn;
                    got.add(x + 0.5, y + 0.5);
                    outside += x + 1 < want.x0 - 1 || x > want.x1 + 1 || y + 1 < want.y0 - 1 || y > want.y1 + 1;
                }
            }
            CAPTURE(file, viewName(view), want.x0, want.x1, want.y0, want.y1, got.x0, got.x1, got.y0, got.y1);
            // Nothing outside the projected box; the drawing reaches its edges (within 2 pixels).
            CHECK(outside == 0);
            CHECK(std::abs(got.x0 - want.x0) < 2.5);
            CHECK(std::abs(got.x1 - want.x1) < 2.5);
            CHECK(std::abs(got.y0 - want.y0) < 2.5);
            CHECK(std::abs(got.y1 - want.y1) < 2.5);
            // Coverage: a full head of hair is a mass, not a few lines (a fifth of the box at
            // least); Curly_100's hundred strands still draw a twentieth.
            const double boxArea = (want.x1 - want.x0) * (want.y1 - want.y0);
            CHECK(double(drawn) > (s.numStrands() >= 1000 ? 0.2 : 0.05) * boxArea);
        }
        // Single strands in the hairstyle's framing: a pixel is drawn within 1.5 pixels of each
        // projected vertex (nothing else occludes a strand drawn alone).
        RenderParams rp;
        rp.view = View::ThreeQuarter;
        rp.width = rp.height = 192;
        rp.frame = frame;
        for (std::size_t i = 0; i < s.numStrands(); i += std::max<std::size_t>(1, s.numStrands() / 5)) {
            StrandSet one;
            one.addStrand(s.data(i), s.size(i));
            const Image im = renderStrands(one, rp);
            const std::vector<bool> m = hairMask(im);
            std::size_t missed = 0;
            for (const Vec3f& p : one.positions) {
                const Vec3d q = projectToImage(Vec3d(p), rp, frame);
                bool near = false;
                for (int dy = -1; dy <= 1 && !near; ++dy)
                    for (int dx = -1; dx <= 1 && !near; ++dx) {
                        const int x = int(q.x()) + dx, y = int(q.y()) + dy;
                        near = x >= 0 && y >= 0 && x < im.width && y < im.height && m[std::size_t(y) * std::size_t(im.width) + std::size_t(x)];
                    }
                missed += !near;
            }
            CAPTURE(file, i);
            CHECK(missed == 0);
        }
    }
}

TEST_CASE("renderStrands: --color-by error colours each vertex by its distance to a reference", "[render]")
{
    // B: a strand on the reference (distance 0: the colour map's low end) and one far from it
    // (beyond the 95th percentile: its high end). Front view, one strand a side.
    StrandSet reference, b;
    std::vector<Vec3f> left, right;
    for (int k = 0; k <= 20; ++k) {
        left.emplace_back(-1.f, -1.f + 0.1f * float(k), 0.f);
        right.emplace_back(1.f, -1.f + 0.1f * float(k), 0.f);
    }
    reference.addStrand(left);
    b.addStrand(left);
    b.addStrand(right);
    RenderParams rp;
    rp.view = View::Front;
    rp.width = rp.height = 200;
    rp.colorBy = ColorBy::Error;
    rp.supersample = 1;  // one-pixel lines of their own colour, not blended with the background
    REQUIRE_THROWS_WITH(renderStrands(b, rp), Catch::Matchers::Contains("needs a reference"));
    rp.reference = &reference;
    const Image im = renderStrands(b, rp);
    const BBox frame = computeBBox(b);
    auto colourAt = [&](const Vec3f& p) {
        const Vec3d q = projectToImage(Vec3d(p), rp, frame);
        // The strand's most saturated pixel near its projection (lines are thin and anti-aliased).
        Vec3f best(1.f);
        for (int dx = -2; dx <= 2; ++dx) {
            const Vec3f c = im.at(int(q.x()) + dx, int(q.y()));
            if (c.x() + c.y() + c.z() < best.x() + best.y() + best.z()) best = c;
        }
        return best;
    };
    const Vec3f low = colorMap(0.f), high = colorMap(1.f), onRef = colourAt(left[10]), far = colourAt(right[10]);
    CAPTURE(low, high, onRef, far);
    CHECK((onRef - low).length() < 0.05f);
    CHECK((far - high).length() < 0.05f);
    // The same image for the reference against itself: every vertex at distance 0.
    const Image same = renderStrands(reference, rp);
    CHECK(same.width == rp.width);
}
