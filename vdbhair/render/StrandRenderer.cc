#include "StrandRenderer.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/Memory.h>
#include <vdbhair/Progress.h>
#include <vdbhair/Quantile.h>
#include <vdbhair/strands/Compare.h>
#include <vdbhair/strands/Measures.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>

namespace vdbhair {

Vec3d defaultFacing(const Vec3d& up)
{
    return std::abs(up.z()) < 0.5 ? Vec3d(0.0, 0.0, 1.0) : Vec3d(0.0, -up.z(), 0.0);
}

View viewFromName(const std::string& name)
{
    if (name == "front") return View::Front;
    if (name == "side") return View::Side;
    if (name == "top") return View::Top;
    if (name == "back") return View::Back;
    if (name == "three-quarter") return View::ThreeQuarter;
    throw ValueError("view '" + name + "' is not one of front, side, top, back, three-quarter");
}

const char* viewName(View v)
{
    switch (v) {
    case View::Front: return "front";
    case View::Side: return "side";
    case View::Top: return "top";
    case View::Back: return "back";
    default: return "three-quarter";
    }
}

const char* colorByName(ColorBy colorBy)
{
    switch (colorBy) {
    case ColorBy::Shaded: return "shaded";
    case ColorBy::Root: return "root";
    case ColorBy::Tangent: return "tangent";
    case ColorBy::Depth: return "depth";
    case ColorBy::Curvature: return "curvature";
    case ColorBy::Strand: return "strand";
    case ColorBy::Error: return "error";
    }
    return "shaded";
}

ColorBy colorByFromName(const std::string& name)
{
    if (name == "shaded") return ColorBy::Shaded;
    if (name == "root") return ColorBy::Root;
    if (name == "tangent") return ColorBy::Tangent;
    if (name == "depth") return ColorBy::Depth;
    if (name == "curvature") return ColorBy::Curvature;
    if (name == "strand") return ColorBy::Strand;
    if (name == "error") return ColorBy::Error;
    throw ParamError<ValueError>({paramName(renderParameters(), "color-by"), " '" + name + "' is not one of shaded, root, tangent, depth, curvature, strand, error"});
}

const ParamTable<RenderParams>& renderParameters()
{
    using P = RenderParams;
    static const ParamTable<P> table = [] {
        ParamTable<P> t;
        auto view = makeParam<P>("view", "The view: orthographic from the front, side, top or back, or three-quarter in perspective", "",
                                 named<P>([](P& p) -> View& { return p.view; }, viewName, viewFromName));
        for (View v : {View::Front, View::Side, View::Top, View::Back, View::ThreeQuarter}) view.choices.push_back(viewName(v));
        t.push_back(view);
        auto width = makeParam<P>("width", "Image width", "pixels", member<P>([](P& p) -> int& { return p.width; }));
        auto height = makeParam<P>("height", "Image height", "pixels", member<P>([](P& p) -> int& { return p.height; }));
        for (Param<P>* size : {&width, &height}) {
            size->min = 1;
            size->max = RenderParams::kMaxSize;
        }
        t.push_back(width);
        t.push_back(height);
        auto colorBy = makeParam<P>("color-by",
                                    "Colouring: lit fibres (shaded), or by root, tangent, depth, curvature, strand, or error (each vertex's "
                                    "distance to the nearest vertex of the reference)", "",
                                    named<P>([](P& p) -> ColorBy& { return p.colorBy; }, colorByName, colorByFromName));
        for (ColorBy c : {ColorBy::Shaded, ColorBy::Root, ColorBy::Tangent, ColorBy::Depth, ColorBy::Curvature, ColorBy::Strand, ColorBy::Error})
            colorBy.choices.push_back(colorByName(c));
        t.push_back(colorBy);
        t.push_back(makeAxisParam<P>("up", "The hairstyle's up axis (z for Yuksel's cyHair models)", [](P& p) -> Vec3d& { return p.up; }));
        // Unset is auto: the zero vector reads and writes it (defaultFacing()).
        auto facing = makeParam<P>("facing", "The axis the face looks along, perpendicular to up (the front view looks at it; cyHair models: "
                                             "up z, facing y)", "",
                                   ParamAccess<P, Vec3d>{[](const P& p) { return p.facing.value_or(Vec3d(0.0)); },
                                                         [](P& p, Vec3d v) {
                                                             if (v == Vec3d(0.0)) p.facing.reset();
                                                             else p.facing = v;
                                                         }});
        facing.zeroMeans = "z, or -y for a z up (Blender's)";
        facing.choices.push_back("auto");
        for (const std::string& n : axisNames()) facing.choices.push_back(n);
        facing.pythonNone = true;
        t.push_back(facing);
        t.push_back(makeParam<P>("title", "Text in the top-left corner", "", member<P>([](P& p) -> std::string& { return p.title; })));
        t.push_back(makeParam<P>("sheet", "One image with the front, side, top and three-quarter views", "", member<P>([](P& p) -> bool& { return p.sheet; })));
        return t;
    }();
    return table;
}

namespace {

/// A camera: world to (image x, image y, depth), x right, y down, in output pixels.
struct Camera
{
    Vec3d right, up, forward, eye;
    bool perspective = false;
    double scale = 1.0, cx = 0.0, cy = 0.0;  // image = centre + scale * projected

    /// The key light: above, a little to the right of and towards the viewer.
    Vec3d light() const { return (up * 0.8 + right * 0.3 - forward * 0.5).unit(); }

    Vec3d project(const Vec3d& p) const
    {
        const Vec3d d = p - eye;
        double u = d.dot(right), v = d.dot(up);
        const double z = d.dot(forward);
        if (perspective) {
            const double zz = std::max(z, 1e-9);
            u /= zz;
            v /= zz;
        }
        return Vec3d(cx + scale * u, cy - scale * v, z);
    }
};

/// @brief The rows of the rotation taking the hairstyle's up to +y and its facing direction to +z
/// (so that its right, up × facing, goes to +x).
/// @throw ValueError unless up and facing are perpendicular unit axes.
std::array<Vec3d, 3> viewRotation(const Vec3d& up, const std::optional<Vec3d>& facingOpt)
{
    const Vec3d facing = facingOpt ? *facingOpt : defaultFacing(up);
    if (std::abs(up.length() - 1.0) > 1e-9 || std::abs(facing.length() - 1.0) > 1e-9 || std::abs(up.dot(facing)) > 1e-9) {
        throw ValueError("render: up (" + std::to_string(up.x()) + ", " + std::to_string(up.y()) + ", " + std::to_string(up.z()) +
                         ") and facing (" + std::to_string(facing.x()) + ", " + std::to_string(facing.y()) + ", " +
                         std::to_string(facing.z()) + ") must be perpendicular unit axes");
    }
    return {up.cross(facing), up, facing};
}

Camera makeCamera(View view, const BBox& box, int width, int height, const RenderParams& params)
{
    const Vec3d lo(box.min), hi(box.max);
    const Vec3d centre = 0.5 * (lo + hi);
    const double radius = std::max(1e-9, 0.5 * (hi - lo).length());
    Camera c;
    switch (view) {
    case View::Front: c.forward = Vec3d(0, 0, -1); c.up = Vec3d(0, 1, 0); break;
    case View::Back: c.forward = Vec3d(0, 0, 1); c.up = Vec3d(0, 1, 0); break;
    case View::Side: c.forward = Vec3d(-1, 0, 0); c.up = Vec3d(0, 1, 0); break;
    case View::Top: c.forward = Vec3d(0, -1, 0); c.up = Vec3d(0, 0, -1); break;
    case View::ThreeQuarter: c.forward = -Vec3d(1.0, 0.6, 1.0).unit(); c.up = Vec3d(0, 1, 0); c.perspective = true; break;
    }
    // The views are defined for +y up: take their directions back to the hairstyle's own axes.
    const std::array<Vec3d, 3> R = viewRotation(params.up, params.facing);
    auto toWorld = [&](const Vec3d& v) { return R[0] * v.x() + R[1] * v.y() + R[2] * v.z(); };  // Rᵀ v
    c.forward = toWorld(c.forward);
    c.up = toWorld(c.up);
    c.right = c.forward.cross(c.up).unit();
    c.up = c.right.cross(c.forward);
    c.eye = centre - c.forward * (c.perspective ? 3.5 * radius : 2.0 * radius);
    // Fit the box's corners with a 6% margin.
    double umin = 1e300, umax = -1e300, vmin = 1e300, vmax = -1e300;
    c.scale = 1.0;
    for (int i = 0; i < 8; ++i) {
        const Vec3d p((i & 1) ? hi.x() : lo.x(), (i & 2) ? hi.y() : lo.y(), (i & 4) ? hi.z() : lo.z());
        const Vec3d q = c.project(p);
        umin = std::min(umin, q.x()); umax = std::max(umax, q.x());
        vmin = std::min(vmin, -q.y()); vmax = std::max(vmax, -q.y());
    }
    const double su = (umax - umin) > 0 ? 0.88 * width / (umax - umin) : 1.0;
    const double sv = (vmax - vmin) > 0 ? 0.88 * height / (vmax - vmin) : 1.0;
    c.scale = std::min(su, sv);
    c.cx = 0.5 * width - c.scale * 0.5 * (umin + umax);
    c.cy = 0.5 * height + c.scale * 0.5 * (vmin + vmax);
    return c;
}

struct Raster
{
    int w, h;
    std::vector<float> depth;
    std::vector<Vec3f> color;
};

/// Per-vertex base colour and whether to light it.
std::vector<Vec3f> baseColors(const StrandSet& s, const RenderParams& p, const Camera& cam, double& lo, double& hi, bool& lit)
{
    const std::size_t nV = s.numVertices();
    std::vector<Vec3f> c(nV, p.hairColor);
    lit = true;
    lo = hi = 0.0;
    switch (p.colorBy) {
    case ColorBy::Shaded:
        if (!s.color.empty()) c = s.color;
        break;
    case ColorBy::Root: {
        const BBox box = computeBBox(s);
        const Vec3f e = box.extent();
        for (std::size_t i = 0; i < s.numStrands(); ++i) {
            Vec3f t = s.root(i) - box.min;
            for (int k = 0; k < 3; ++k) t[k] = e[k] > 0.f ? t[k] / e[k] : 0.5f;
            const Vec3f col(0.15f + 0.8f * t.x(), 0.15f + 0.8f * t.y(), 0.15f + 0.8f * t.z());
            std::fill(c.begin() + std::ptrdiff_t(s.begin(i)), c.begin() + std::ptrdiff_t(s.end(i)), col);
        }
        break;
    }
    case ColorBy::Strand:
        for (std::size_t i = 0; i < s.numStrands(); ++i) {
            std::fill(c.begin() + std::ptrdiff_t(s.begin(i)), c.begin() + std::ptrdiff_t(s.end(i)), idColor(i));
        }
        break;
    case ColorBy::Tangent: {
        lit = false;
        const std::vector<Vec3f> t = computeTangents(s);
        for (std::size_t v = 0; v < nV; ++v) c[v] = fromSrgb(Vec3f(std::abs(t[v].x()), std::abs(t[v].y()), std::abs(t[v].z())));
        break;
    }
    case ColorBy::Depth: {
        lit = false;
        std::vector<float> d(nV);
        lo = 1e300; hi = -1e300;
        for (std::size_t v = 0; v < nV; ++v) {
            d[v] = float(cam.project(Vec3d(s.positions[v])).z());
            lo = std::min(lo, double(d[v])); hi = std::max(hi, double(d[v]));
        }
        for (std::size_t v = 0; v < nV; ++v) c[v] = colorMap(hi > lo ? float((d[v] - lo) / (hi - lo)) : 0.5f);
        break;
    }
    case ColorBy::Curvature: {
        lit = false;
        std::vector<float> k(nV);
        for (std::size_t i = 0; i < s.numStrands(); ++i) curvatureProfile(s.data(i), s.size(i), k.data() + s.begin(i));
        lo = lowerQuantile(k, 0.05);
        hi = lowerQuantile(k, 0.95);
        for (std::size_t v = 0; v < nV; ++v) c[v] = colorMap(hi > lo ? float((k[v] - lo) / (hi - lo)) : 0.5f);
        break;
    }
    case ColorBy::Error: {
        lit = false;
        if (nV == 0) break;
        const std::vector<double> d = nearestVertexDistances(StrandIndex(s), StrandIndex(*p.reference));
        lo = 0.0;
        hi = lowerQuantile(d, 0.95);
        for (std::size_t v = 0; v < nV; ++v) c[v] = colorMap(hi > 0.0 ? float(std::min(1.0, d[v] / hi)) : 0.f);
        break;
    }
    }
    return c;
}

/// Kajiya–Kay fibre shading for tangent @a t (view space), light @a l, eye direction @a e.
Vec3f shade(const Vec3f& base, const Vec3d& t, const Vec3d& l, const Vec3d& e)
{
    const double tl = t.dot(l), te = t.dot(e);
    const double sl = std::sqrt(std::max(0.0, 1.0 - tl * tl)), se = std::sqrt(std::max(0.0, 1.0 - te * te));
    const double diffuse = sl;
    // The specular lobe, (cos)^40 by squaring: x^40 = x^32 · x^8 (std::pow was a tenth of a render).
    const double x = std::max(0.0, tl * te + sl * se), x2 = x * x, x4 = x2 * x2, x8 = x4 * x4, x32 = (x8 * x8) * (x8 * x8);
    const double spec = x32 * x8;
    const float k = float(0.35 + 0.75 * diffuse);
    return Vec3f(base.x() * k, base.y() * k, base.z() * k) + Vec3f(float(0.25 * spec));
}

/// Draw every segment of @a s into the supersampled raster (bands in parallel).
/// @a vcolor holds a colour per vertex, or is null for @a uniform everywhere.
void rasterize(Raster& r, const StrandSet& s, const Vec3d* proj, const Vec3f* vcolor, const Vec3f& uniform,
               const Vec3f* shadeDir, bool lit, const Camera& cam, bool onTop, int thickness,
               openvdb::util::NullInterrupter* interrupter, const std::string& stage)
{
    const int bands = 32, bandRows = (r.h + bands - 1) / bands;
    const Vec3d light = cam.light();
    const Vec3d eye = -cam.forward;
    // Bin segments by band, in segment order so that each band draws in a fixed order: fixed
    // chunks of strands binned in parallel, then each band's lists joined in chunk order.
    const std::size_t chunks = std::min<std::size_t>(64, std::max<std::size_t>(1, s.numStrands()));
    std::vector<std::vector<std::vector<std::uint32_t>>> chunkBins(chunks, std::vector<std::vector<std::uint32_t>>(std::size_t(bands)));
    tbb::parallel_for(std::size_t(0), chunks, [&](std::size_t c) {
        const std::size_t first = s.numStrands() * c / chunks, last = s.numStrands() * (c + 1) / chunks;
        auto& mine = chunkBins[c];
        for (std::size_t i = first; i < last; ++i) {
            for (std::size_t v = s.begin(i); v + 1 < s.end(i); ++v) {
                const double y0 = std::min(proj[v].y(), proj[v + 1].y()) - thickness, y1 = std::max(proj[v].y(), proj[v + 1].y()) + thickness;
                if (y1 < 0 || y0 >= r.h || (cam.perspective && proj[v].z() <= 0)) continue;
                const int b0 = std::max(0, int(y0) / bandRows), b1 = std::min(bands - 1, int(y1) / bandRows);
                for (int b = b0; b <= b1; ++b) mine[std::size_t(b)].push_back(std::uint32_t(v));
            }
        }
    });
    std::vector<std::vector<std::uint32_t>> bins(static_cast<std::size_t>(bands));
    tbb::parallel_for(0, bands, [&](int b) {
        std::size_t n = 0;
        for (const auto& cb : chunkBins) n += cb[std::size_t(b)].size();
        bins[std::size_t(b)].reserve(n);
        for (auto& cb : chunkBins) {
            bins[std::size_t(b)].insert(bins[std::size_t(b)].end(), cb[std::size_t(b)].begin(), cb[std::size_t(b)].end());
            std::vector<std::uint32_t>().swap(cb[std::size_t(b)]);
        }
    });
    std::uint64_t binned = 0;
    for (const auto& bin : bins) binned += bin.size();
    ProgressCounter progress(interrupter, stage.c_str(), binned, "segments");
    tbb::parallel_for(tbb::blocked_range<int>(0, bands, 1), [&](const tbb::blocked_range<int>& br) {
        for (int b = br.begin(); b != br.end(); ++b) {
            if (progress.stopped() || progress.add(bins[std::size_t(b)].size())) return;
            const int rowLo = b * bandRows, rowHi = std::min(r.h, rowLo + bandRows);
            for (std::uint32_t v : bins[std::size_t(b)]) {
                const Vec3d a = proj[v], c = proj[v + 1];
                Vec3f col0 = vcolor ? vcolor[v] : uniform, col1 = vcolor ? vcolor[v + 1] : uniform;
                if (lit) {
                    const Vec3d t(shadeDir[v]);
                    col0 = shade(col0, t, light, eye);
                    col1 = shade(col1, t, light, eye);
                }
                const double dx = c.x() - a.x(), dy = c.y() - a.y();
                const int n = std::max(1, int(std::ceil(std::max(std::abs(dx), std::abs(dy)))));
                for (int k = 0; k <= n; ++k) {
                    const double f = double(k) / n;
                    const int px = int(std::floor(a.x() + f * dx)), py0 = int(std::floor(a.y() + f * dy));
                    const float z = float(a.z() + f * (c.z() - a.z()));
                    for (int o = 0; o < thickness; ++o) {
                        const int py = py0 + o - thickness / 2;
                        if (px < 0 || px >= r.w || py < rowLo || py >= rowHi) continue;
                        const std::size_t idx = std::size_t(py) * std::size_t(r.w) + std::size_t(px);
                        if (onTop || z < r.depth[idx]) {
                            r.depth[idx] = onTop ? -std::numeric_limits<float>::max() : z;
                            r.color[idx] = col0 + (col1 - col0) * float(f);
                        }
                    }
                }
            }
        }
    });
    if (progress.stopped()) throw InterruptedError("renderStrands: interrupted");
}

/// Draw the triangles of @a mesh into the raster's depth and colour (bands in parallel), lit
/// two-sided by the strands' light.
void rasterizeMesh(Raster& r, const TriangleMesh& mesh, const Camera& cam, const Vec3f& color,
                   openvdb::util::NullInterrupter* interrupter)
{
    std::vector<Vec3d> proj(mesh.vertices.size());
    for (std::size_t v = 0; v < proj.size(); ++v) proj[v] = cam.project(Vec3d(mesh.vertices[v]));
    const Vec3d light = cam.light();
    const int bands = 32, bandRows = (r.h + bands - 1) / bands;
    ProgressCounter progress(interrupter, "rendering the head", std::uint64_t(bands), "bands");
    tbb::parallel_for(tbb::blocked_range<int>(0, bands, 1), [&](const tbb::blocked_range<int>& br) {
        for (int band = br.begin(); band != br.end(); ++band) {
            if (progress.stopped() || progress.add(1)) return;
            const int rowLo = band * bandRows, rowHi = std::min(r.h, rowLo + bandRows);
            for (const auto& tri : mesh.triangles) {
                const Vec3d &a = proj[tri[0]], &b = proj[tri[1]], &c = proj[tri[2]];
                if (cam.perspective && (a.z() <= 0 || b.z() <= 0 || c.z() <= 0)) continue;
                const double y0 = std::min({a.y(), b.y(), c.y()}), y1 = std::max({a.y(), b.y(), c.y()});
                if (y1 < rowLo || y0 >= rowHi) continue;
                const double area = (b.x() - a.x()) * (c.y() - a.y()) - (b.y() - a.y()) * (c.x() - a.x());
                if (area == 0.0) continue;
                const Vec3d n = (Vec3d(mesh.vertices[tri[1]]) - Vec3d(mesh.vertices[tri[0]]))
                                    .cross(Vec3d(mesh.vertices[tri[2]]) - Vec3d(mesh.vertices[tri[0]]));
                const double len = n.length();
                const float lit = len > 0.0 ? float(0.35 + 0.65 * std::abs(n.dot(light)) / len) : 0.35f;
                const Vec3f shaded = color * lit;
                const int px0 = std::max(0, int(std::floor(std::min({a.x(), b.x(), c.x()}))));
                const int px1 = std::min(r.w - 1, int(std::ceil(std::max({a.x(), b.x(), c.x()}))));
                const int py0 = std::max(rowLo, int(std::floor(y0))), py1 = std::min(rowHi - 1, int(std::ceil(y1)));
                for (int y = py0; y <= py1; ++y) {
                    for (int x = px0; x <= px1; ++x) {
                        // Barycentric weights of the pixel centre; inside when all share area's sign.
                        const double sx = x + 0.5, sy = y + 0.5;
                        const double w0 = ((b.x() - sx) * (c.y() - sy) - (b.y() - sy) * (c.x() - sx)) / area;
                        const double w1 = ((c.x() - sx) * (a.y() - sy) - (c.y() - sy) * (a.x() - sx)) / area;
                        const double w2 = 1.0 - w0 - w1;
                        if (w0 < 0.0 || w1 < 0.0 || w2 < 0.0) continue;
                        const float z = float(w0 * a.z() + w1 * b.z() + w2 * c.z());
                        const std::size_t idx = std::size_t(y) * std::size_t(r.w) + std::size_t(x);
                        if (z < r.depth[idx]) {
                            r.depth[idx] = z;
                            r.color[idx] = shaded;
                        }
                    }
                }
            }
        }
    });
    if (progress.stopped()) throw InterruptedError("renderStrands: interrupted");
}

/// The box a render fits by default: the strands, the guides and the head.
BBox renderFrame(const StrandSet& strands, const RenderParams& params)
{
    BBox box = computeBBox(strands);
    for (const BBox& b : {params.guides ? computeBBox(*params.guides) : BBox(), params.head ? meshBBox(*params.head) : BBox()}) {
        if (!b.empty()) { box.expand(b.min); box.expand(b.max); }
    }
    return box;
}

void checkSize(const RenderParams& p)
{
    if (p.width < 1 || p.height < 1 || p.width > RenderParams::kMaxSize || p.height > RenderParams::kMaxSize) {
        const std::string most = std::to_string(RenderParams::kMaxSize);
        throw ValueError("image size " + std::to_string(p.width) + "x" + std::to_string(p.height) +
                         " must be between 1x1 and " + most + "x" + most + " pixels");
    }
    if (p.supersample < 1 || p.supersample > 8) throw ValueError("supersampling " + std::to_string(p.supersample) + " must be 1 to 8");
    if (p.colorBy == ColorBy::Error && (!p.reference || p.reference->positions.empty())) {
        throw ParamError<ValueError>({paramName(renderParameters(), "color-by"), " error needs a reference hairstyle with vertices to measure the distance to"});
    }
}

} // namespace

Vec3d projectToImage(const Vec3d& world, const RenderParams& params, const BBox& frame)
{
    checkSize(params);
    const int S = params.supersample;
    const Vec3d q = makeCamera(params.view, frame, params.width * S, params.height * S, params).project(world);
    return Vec3d(q.x() / S, q.y() / S, q.z());
}

Image renderStrands(const StrandSet& strands, const RenderParams& params)
{
    checkSize(params);
    const int S = params.supersample;
    const BBox box = params.frame ? *params.frame : renderFrame(strands, params);
    Image out(params.width, params.height, params.background);
    if (box.empty()) return out;
    const Camera cam = makeCamera(params.view, box, params.width * S, params.height * S, params);

    Raster r{params.width * S, params.height * S, {}, {}};
    const std::size_t pixels = std::size_t(r.w) * std::size_t(r.h);
    reserveHugePages(r.depth, pixels);
    reserveHugePages(r.color, pixels);
    r.depth.assign(pixels, std::numeric_limits<float>::max());
    r.color.assign(pixels, params.background);

    auto drawSet = [&](const StrandSet& s, const std::optional<Vec3f>& fixed, bool onTop, int thickness, double& lo, double& hi) {
        // Per-vertex arrays left uninitialized (Vec3's default constructor writes nothing) and
        // first written in parallel: zero-filling them serially cost more than drawing.
        // Fresh pages cost a fault each (Memory.h): ask for huge ones.
        const std::unique_ptr<Vec3d[]> proj(new Vec3d[s.numVertices()]);
        adviseHugePages(proj.get(), s.numVertices() * sizeof(Vec3d));
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, s.numVertices(), 4096), [&](const tbb::blocked_range<std::size_t>& br) {
            for (std::size_t v = br.begin(); v != br.end(); ++v) proj[v] = cam.project(Vec3d(s.positions[v]));
        });
        bool lit = true;
        std::vector<Vec3f> colors;
        const Vec3f* vcolor = nullptr;  // null: one colour for every vertex
        Vec3f uniform = params.hairColor;
        if (fixed) uniform = *fixed;
        else if (params.colorBy == ColorBy::Shaded) vcolor = s.color.empty() ? nullptr : s.color.data();
        else vcolor = (colors = baseColors(s, params, cam, lo, hi, lit)).data();
        // Segment directions in view space for the fibre shading.
        const std::unique_ptr<Vec3f[]> dirs(new Vec3f[s.numVertices()]);
        adviseHugePages(dirs.get(), s.numVertices() * sizeof(Vec3f));
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, s.numStrands(), 256), [&](const tbb::blocked_range<std::size_t>& br) {
            for (std::size_t i = br.begin(); i != br.end(); ++i) {
                for (std::size_t v = s.begin(i); v < s.end(i); ++v) {
                    dirs[v] = Vec3f(0.f);
                    if (v + 1 == s.end(i)) continue;
                    const Vec3d d = Vec3d(s.positions[v + 1]) - Vec3d(s.positions[v]);
                    const double len = d.length();
                    if (len > 0) dirs[v] = Vec3f(float(d.dot(cam.right) / len), float(d.dot(cam.up) / len), float(d.dot(cam.forward) / len));
                }
            }
        });
        // Shading works in view space: express light and eye there too.
        Camera viewCam = cam;
        viewCam.right = Vec3d(1, 0, 0); viewCam.up = Vec3d(0, 1, 0); viewCam.forward = Vec3d(0, 0, 1);
        const std::string stage = std::string("rendering the ") + viewName(params.view) + " view" + (onTop ? " (guides)" : "");
        rasterize(r, s, proj.get(), vcolor, uniform, dirs.get(), lit, viewCam, onTop, thickness, params.interrupter, stage);
    };
    double lo = 0, hi = 0, glo = 0, ghi = 0;
    if (params.head) rasterizeMesh(r, *params.head, cam, params.headColor, params.interrupter);
    drawSet(strands, std::nullopt, false, 1, lo, hi);
    if (params.guides) drawSet(*params.guides, params.guideColor, true, std::max(2, S), glo, ghi);

    // Downsample: the mean of each S x S block.
    tbb::parallel_for(tbb::blocked_range<int>(0, params.height, 8), [&](const tbb::blocked_range<int>& br) {
        for (int y = br.begin(); y != br.end(); ++y) {
            for (int x = 0; x < params.width; ++x) {
                Vec3f sum(0.f);
                for (int j = 0; j < S; ++j) {
                    for (int i = 0; i < S; ++i) sum += r.color[std::size_t(y * S + j) * std::size_t(r.w) + std::size_t(x * S + i)];
                }
                out.set(x, y, sum / float(S * S));
            }
        }
    });
    const int text = std::max(10, std::min(24, params.height / 40));
    if (!params.title.empty()) drawText(out, text / 2, text + text / 2, params.title, text, Vec3f(0.f));
    if (params.colorBy == ColorBy::Depth || params.colorBy == ColorBy::Curvature || params.colorBy == ColorBy::Error) {
        const int bh = params.height / 3, bw = std::max(8, params.width / 50);
        drawColorBar(out, params.width - bw - 8 * text / 2 - 8, params.height - bh - text, bw, bh, lo, hi,
                     params.colorBy == ColorBy::Depth ? "depth" : params.colorBy == ColorBy::Curvature ? "curvature" : "distance");
    }
    return out;
}

Image renderSheet(const StrandSet& strands, const RenderParams& params)
{
    checkSize(params);
    RenderParams p = params;
    p.width = std::max(1, params.width / 2);
    p.height = std::max(1, params.height / 2);
    if (!p.frame) {
        p.frame = renderFrame(strands, params);
    }
    Image sheet(params.width, params.height, params.background);
    const View views[4] = {View::Front, View::Side, View::Top, View::ThreeQuarter};
    for (int i = 0; i < 4; ++i) {
        p.view = views[i];
        p.title = (params.title.empty() ? std::string() : params.title + ": ") + viewName(views[i]);
        sheet.paste(renderStrands(strands, p), (i % 2) * p.width, (i / 2) * p.height);
    }
    return sheet;
}

} // namespace vdbhair
