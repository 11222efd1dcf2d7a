#include "SliceRenderer.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/field/Streamline.h>
#include <vdbhair/io/VdbFile.h>
#include <vdbhair/render/Image.h>

#include <openvdb/openvdb.h>
#include <openvdb/points/PointDataGrid.h>
#include <openvdb/tools/Interpolation.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <vector>

namespace vdbhair {

namespace {

std::string num(double v)
{
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.4g", v);
    return buf;
}

const char* axisName(int a) { return a == 0 ? "x" : a == 1 ? "y" : "z"; }

/// The plot's axes in world space: u to the right, v up, as `vdbhair render`'s views.
struct PlaneAxes
{
    int uAxis, vAxis;
    double uSign, vSign;
};

PlaneAxes planeAxes(int axis)
{
    if (axis == 2) return {0, 1, 1.0, 1.0};   // front: x right, y up
    if (axis == 0) return {2, 1, -1.0, 1.0};  // side: -z right, y up
    return {0, 2, 1.0, -1.0};                 // top: x right, -z up
}

/// Anti-aliased line of @a halfWidth pixels blended over the image, clipped to [x0, x1) × [y0, y1).
void drawLine(Image& img, double ax, double ay, double bx, double by, double halfWidth, const Vec3f& color, float alpha,
              int x0, int y0, int x1, int y1)
{
    const double r = halfWidth + 1.0;
    const int minX = std::max(x0, int(std::floor(std::min(ax, bx) - r))), maxX = std::min(x1 - 1, int(std::ceil(std::max(ax, bx) + r)));
    const int minY = std::max(y0, int(std::floor(std::min(ay, by) - r))), maxY = std::min(y1 - 1, int(std::ceil(std::max(ay, by) + r)));
    const double dx = bx - ax, dy = by - ay, len2 = dx * dx + dy * dy;
    for (int y = minY; y <= maxY; ++y) {
        for (int x = minX; x <= maxX; ++x) {
            const double px = x + 0.5 - ax, py = y + 0.5 - ay;
            const double t = len2 > 0.0 ? std::max(0.0, std::min(1.0, (px * dx + py * dy) / len2)) : 0.0;
            const double ex = px - t * dx, ey = py - t * dy;
            const double cover = std::max(0.0, std::min(1.0, halfWidth + 0.5 - std::sqrt(ex * ex + ey * ey)));
            if (cover <= 0.0) continue;
            const float a = alpha * float(cover);
            const Vec3f old = img.at(x, y);
            img.set(x, y, old * (1.f - a) + color * a);
        }
    }
}

/// What the renderer needs of a grid, whatever its value type.
struct Sampled
{
    bool vector = false;
    /// Nearest voxel at a world point: whether it is active, and its value (x only for scalars).
    std::function<bool(const openvdb::Vec3d&, openvdb::Vec3d&)> nearest;
    /// Trilinear sample at a world point (vectors only).
    std::function<openvdb::Vec3d(const openvdb::Vec3d&)> linear;
};

template<typename GridT>
Sampled makeVectorSampler(const GridT& grid)
{
    Sampled s;
    s.vector = true;
    s.nearest = [&grid](const openvdb::Vec3d& w, openvdb::Vec3d& out) {
        typename GridT::ConstAccessor acc = grid.getConstAccessor();  // cheap; keeps the sampler thread-free
        const openvdb::Coord ijk = openvdb::Coord::round(grid.transform().worldToIndex(w));
        typename GridT::ValueType v;
        const bool on = acc.probeValue(ijk, v);
        out = openvdb::Vec3d(double(v[0]), double(v[1]), double(v[2]));
        return on;
    };
    s.linear = [&grid](const openvdb::Vec3d& w) {
        const auto v = openvdb::tools::BoxSampler::sample(grid.tree(), grid.transform().worldToIndex(w));
        return openvdb::Vec3d(double(v[0]), double(v[1]), double(v[2]));
    };
    return s;
}

template<typename GridT>
Sampled makeScalarSampler(const GridT& grid)
{
    Sampled s;
    s.nearest = [&grid](const openvdb::Vec3d& w, openvdb::Vec3d& out) {
        typename GridT::ConstAccessor acc = grid.getConstAccessor();
        const openvdb::Coord ijk = openvdb::Coord::round(grid.transform().worldToIndex(w));
        typename GridT::ValueType v;
        const bool on = acc.probeValue(ijk, v);
        out = openvdb::Vec3d(double(v), 0.0, 0.0);
        return on;
    };
    return s;
}

/// The in-plane projection of a vector slice's field at a world point, as a sampler of the
/// streamline engine (field/Streamline.h): Left off the grid's active voxels, Vanished where the
/// in-plane part is no longer than @a minLength.
struct InPlaneSampler
{
    const Sampled& s;
    int axis;
    double minLength;

    SampleStatus direction(const openvdb::Vec3d& w, openvdb::Vec3d& d)
    {
        openvdb::Vec3d probe;
        if (!s.nearest(w, probe)) return SampleStatus::Left;
        openvdb::Vec3d v = s.linear(w);
        v[axis] = 0.0;
        const double len = v.length();
        if (!(len > minLength)) return SampleStatus::Vanished;
        d = v / len;
        return SampleStatus::Ok;
    }
};

/// The slice, AXIS=WORLD: no declared parameter (SliceParams holds it parsed), named as inspect's
/// --slice and Python's slice= keyword.
const ParamName kSliceName{"--slice", "slice"};

void checkSliceParams(const SliceParams& params, const std::string& where)
{
    if (params.axis < 0 || params.axis > 2) {
        throw ParamError<ValueError>({where + ": ", kSliceName, " axis " + std::to_string(params.axis) + " is not 0, 1 or 2"});
    }
    checkParams(sliceParameters(), params, ParamSpelling::Keyword, where);
}

/// The sampler of a voxel grid of a type slices show; @a gw names the grid in errors.
Sampled samplerOf(const openvdb::GridBase& base, const std::string& gw)
{
    using namespace openvdb;
    if (base.isType<points::PointDataGrid>()) {
        throw ValueError(gw + " holds points; slices show voxel grids (render the strands with 'vdbhair render')");
    }
    Sampled s;
    const bool vec = base.apply<TypeList<Vec3SGrid, Vec3DGrid>>([&](const auto& g) { s = makeVectorSampler(g); });
    const bool sca = !vec && base.apply<TypeList<FloatGrid, DoubleGrid, Int32Grid, Int64Grid, BoolGrid>>(
                                 [&](const auto& g) { s = makeScalarSampler(g); });
    if (!vec && !sca) throw ValueError(gw + " holds " + base.valueType() + " values; slices show float, double, int, bool and vec3 grids");
    return s;
}

/// World bounds of the active voxels (voxel extents), from the 8 corners of the index box.
openvdb::BBoxd worldBoundsOf(const openvdb::CoordBBox& ibox, const openvdb::math::Transform& xf)
{
    openvdb::BBoxd wbox;
    for (int c = 0; c < 8; ++c) {
        const Vec3d corner((c & 1 ? ibox.max().x() + 0.5 : ibox.min().x() - 0.5), (c & 2 ? ibox.max().y() + 0.5 : ibox.min().y() - 0.5),
                           (c & 4 ? ibox.max().z() + 0.5 : ibox.min().z() - 0.5));
        wbox.expand(xf.indexToWorld(corner));
    }
    return wbox;
}

/// The plot of a slice: its world window on the plane, its size in pixels and where it sits in
/// the image (a header above, the legend's panel to the right).
struct SlicePlot
{
    static constexpr int kMargin = 12, kHeader = 34, kPanel = 190;
    int axis;
    double world;
    PlaneAxes pa;
    double uLo, uHi, vLo, vHi;
    int plotW, plotH;
    double scale;  ///< pixels per world unit
    int imgW, imgH;
    int x0 = kMargin, y0 = kHeader;

    SlicePlot(int axis_, double world_, int width, const openvdb::BBoxd& wbox)
        : axis(axis_), world(world_), pa(planeAxes(axis_))
    {
        uLo = pa.uSign > 0 ? wbox.min()[pa.uAxis] : -wbox.max()[pa.uAxis];
        uHi = pa.uSign > 0 ? wbox.max()[pa.uAxis] : -wbox.min()[pa.uAxis];
        vLo = pa.vSign > 0 ? wbox.min()[pa.vAxis] : -wbox.max()[pa.vAxis];
        vHi = pa.vSign > 0 ? wbox.max()[pa.vAxis] : -wbox.min()[pa.vAxis];
        plotW = width;
        scale = double(plotW) / (uHi - uLo);
        plotH = std::max(16, std::min(16384, int(std::lround((vHi - vLo) * scale))));
        imgW = kMargin + plotW + kPanel;
        imgH = kHeader + std::max(plotH, 400) + kMargin;  // room for the legend
    }
    /// Plot pixel coordinates (continuous) to world.
    Vec3d worldAt(double px, double py) const
    {
        Vec3d w(0.0);
        w[axis] = world;
        w[pa.uAxis] = pa.uSign * (uLo + px / scale);
        w[pa.vAxis] = pa.vSign * (vHi - py / scale);
        return w;
    }
    void pixelAt(const Vec3d& w, double& px, double& py) const
    {
        px = (pa.uSign * w[pa.uAxis] - uLo) * scale;
        py = (vHi - pa.vSign * w[pa.vAxis]) * scale;
    }
};

/// Every plot pixel's nearest voxel, and the range of the values (vector lengths) shown.
struct PixelSamples
{
    std::vector<Vec3d> values;
    std::vector<unsigned char> active;
    double lo = std::numeric_limits<double>::max(), hi = -std::numeric_limits<double>::max();
};

PixelSamples samplePixels(const SlicePlot& plot, const Sampled& s)
{
    PixelSamples ps;
    ps.values.resize(std::size_t(plot.plotW) * std::size_t(plot.plotH));
    ps.active.assign(ps.values.size(), 0);
    for (int py = 0; py < plot.plotH; ++py) {
        for (int px = 0; px < plot.plotW; ++px) {
            const std::size_t i = std::size_t(py) * std::size_t(plot.plotW) + std::size_t(px);
            Vec3d v;
            if (!s.nearest(plot.worldAt(px + 0.5, py + 0.5), v)) continue;
            ps.active[i] = 1;
            ps.values[i] = v;
            const double q = s.vector ? v.length() : v.x();
            if (std::isfinite(q)) { ps.lo = std::min(ps.lo, q); ps.hi = std::max(ps.hi, q); }
        }
    }
    if (!(ps.hi >= ps.lo)) { ps.lo = ps.hi = 0.0; }
    return ps;
}

/// Active voxels of the slice's voxel layer (counted in index space, not pixels); 0 for a
/// non-linear transform.
std::size_t activeVoxelsOfLayer(const openvdb::GridBase& base, const openvdb::CoordBBox& ibox, int axis, int indexPlane)
{
    using namespace openvdb;
    std::size_t n = 0;
    if (base.transform().isLinear()) {
        Coord a = ibox.min(), b = ibox.max();
        a[axis] = b[axis] = indexPlane;
        const CoordBBox layer(a, b);
        base.apply<TypeList<Vec3SGrid, Vec3DGrid, FloatGrid, DoubleGrid, Int32Grid, Int64Grid, BoolGrid>>([&](const auto& g) {
            auto acc = g.getConstAccessor();
            for (auto ijk = layer.begin(); ijk; ++ijk) n += acc.isValueOn(*ijk) ? 1 : 0;
        });
    }
    return n;
}

/// The plot's pixels: vectors by direction (RGB of |x|, |y|, |z| or HSV of the in-plane angle)
/// and length (brightness, relative to @a ref), scalars through the colour map, inactive grey.
void paintPixels(Image& image, const SlicePlot& plot, const PixelSamples& ps, const Sampled& s, SliceColor color, double ref)
{
    const Vec3f inactive(0.80f);
    const PlaneAxes& pa = plot.pa;
    const double lo = ps.lo, hi = ps.hi;
    for (int py = 0; py < plot.plotH; ++py) {
        for (int px = 0; px < plot.plotW; ++px) {
            const std::size_t i = std::size_t(py) * std::size_t(plot.plotW) + std::size_t(px);
            Vec3f c = inactive;
            if (ps.active[i]) {
                const Vec3d& v = ps.values[i];
                if (s.vector) {
                    const double len = v.length();
                    const double bright = len > 0.0 ? std::min(1.0, len / ref) : 0.0;
                    if (color == SliceColor::Rgb) {
                        c = len > 0.0 ? fromSrgb(Vec3f(float(std::abs(v.x()) / len), float(std::abs(v.y()) / len), float(std::abs(v.z()) / len)) * float(bright))
                                      : Vec3f(0.f);
                    } else {
                        const double du = pa.uSign * v[pa.uAxis], dv = pa.vSign * v[pa.vAxis];
                        const double inPlane = std::sqrt(du * du + dv * dv);
                        const double hue = std::atan2(dv, du) / (2.0 * M_PI);
                        c = hsvColor(hue, len > 0.0 ? inPlane / len : 0.0, bright);
                    }
                } else {
                    c = colorMap(hi > lo ? float((v.x() - lo) / (hi - lo)) : 0.5f);
                }
            }
            image.set(plot.x0 + px, plot.y0 + py, c);
        }
    }
}

/// Streamlines of the in-plane projection, seeded evenly over the active pixels: the streamline
/// engine's midpoint rule at its default step (of the smallest voxel side), both ways from each
/// seed, stopping where a step's stages reverse (a sink, or a sign flip). Returns how many were drawn.
int drawStreamlines(Image& image, const SlicePlot& plot, const PixelSamples& ps, const Sampled& s, const Vec3d& voxelSize,
                    int count, double ref)
{
    std::vector<std::size_t> on;
    for (std::size_t i = 0; i < ps.active.size(); ++i) if (ps.active[i]) on.push_back(i);
    const Vec3d& vs = voxelSize;
    StreamlineRules rules;
    rules.integrator = Integrator::RK2;
    rules.reversal = StageReversal::Stop;
    rules.step = kDefaultStepVoxels * std::min(vs.x(), std::min(vs.y(), vs.z()));
    rules.maxSteps = std::size_t(std::max(0.0, std::min(1e6, 4.0 * ((plot.uHi - plot.uLo) + (plot.vHi - plot.vLo)) / rules.step)));
    const double length = double(rules.maxSteps + 1) * rules.step;  // the step cap ends every streamline
    InPlaneSampler forward{s, plot.axis, 1e-6 * ref};
    ReversedSampler<InPlaneSampler> backward(forward);
    const int n = rules.maxSteps ? std::min<int>(count, int(on.size())) : 0;
    const int x0 = plot.x0, y0 = plot.y0;
    int drawn = 0;
    std::vector<Vec3d> half;
    for (int k = 0; k < n; ++k) {
        const std::size_t i = on[std::size_t((double(k) + 0.5) * double(on.size()) / double(n))];
        const Vec3d seed = plot.worldAt(double(i % std::size_t(plot.plotW)) + 0.5, double(i / std::size_t(plot.plotW)) + 0.5);
        traceStreamline(backward, seed, length, rules, half);
        std::vector<Vec3d> line(half.rbegin(), half.rend());
        traceStreamline(forward, seed, length, rules, half);
        line.insert(line.end(), half.begin() + 1, half.end());
        if (line.size() < 2) continue;
        ++drawn;
        for (int pass = 0; pass < 2; ++pass) {
            const double hw = pass == 0 ? 1.4 : 0.6;
            const Vec3f col = pass == 0 ? Vec3f(0.f) : Vec3f(1.f);
            const float alpha = pass == 0 ? 0.55f : 0.95f;
            for (std::size_t j = 0; j + 1 < line.size(); ++j) {
                double ax, ay, bx, by;
                plot.pixelAt(line[j], ax, ay);
                plot.pixelAt(line[j + 1], bx, by);
                drawLine(image, x0 + ax, y0 + ay, x0 + bx, y0 + by, hw, col, alpha, x0, y0, x0 + plot.plotW, y0 + plot.plotH);
            }
        }
    }
    return drawn;
}

/// The title above the plot and, to its right, the axes and the legend of the colours.
void drawTitleAndLegend(SliceResult& res, const SlicePlot& plot, const Sampled& s, SliceColor color, const std::string& gridName,
                        const std::string& valueType)
{
    const PlaneAxes& pa = plot.pa;
    const double lo = res.lo, hi = res.hi;
    const char* uName = axisName(pa.uAxis);
    const char* vName = axisName(pa.vAxis);
    drawText(res.image, SlicePlot::kMargin, 22,
             "grid '" + gridName + "'  " + axisName(plot.axis) + " = " + num(plot.world) + "  (voxel layer " + std::to_string(res.indexPlane) +
                 ", " + std::to_string(res.activeVoxels) + " active)",
             16, Vec3f(0.f));
    const int lx = plot.x0 + plot.plotW + 16;
    int ly = plot.y0 + 14;
    drawText(res.image, lx, ly, std::string("right: ") + (pa.uSign < 0 ? "-" : "+") + uName, 13, Vec3f(0.f));
    drawText(res.image, lx, ly + 18, std::string("up: ") + (pa.vSign < 0 ? "-" : "+") + vName, 13, Vec3f(0.f));
    drawText(res.image, lx, ly + 36, "pixel: " + num(1.0 / plot.scale) + " units", 13, Vec3f(0.f));
    ly += 70;
    if (s.vector) {
        if (color == SliceColor::Rgb) {
            drawText(res.image, lx, ly, "colour = |direction|", 13, Vec3f(0.f));
            const char* names[3] = {"red: |x|", "green: |y|", "blue: |z|"};
            const Vec3f cols[3] = {Vec3f(0.8f, 0.f, 0.f), Vec3f(0.f, 0.55f, 0.f), Vec3f(0.f, 0.f, 0.9f)};
            for (int a = 0; a < 3; ++a) drawText(res.image, lx, ly + 18 * (a + 1), names[a], 13, cols[a]);
            ly += 90;
        } else {
            drawText(res.image, lx, ly, "hue = in-plane angle", 13, Vec3f(0.f));
            drawText(res.image, lx, ly + 18, "pale = out of plane", 13, Vec3f(0.f));
            const int r = 45, cx = lx + 60, cy = ly + 40 + r;
            for (int y = -r; y <= r; ++y) {
                for (int x = -r; x <= r; ++x) {
                    const double d = std::sqrt(double(x * x + y * y));
                    if (d > r || cx + x >= plot.imgW || cy + y >= plot.imgH) continue;
                    res.image.set(cx + x, cy + y, hsvColor(std::atan2(-double(y), double(x)) / (2.0 * M_PI), d / r, 1.0));
                }
            }
            drawText(res.image, cx + r + 4, cy + 5, std::string("+") + uName, 13, Vec3f(0.f));
            drawText(res.image, cx - 8, cy - r - 4, std::string("+") + vName, 13, Vec3f(0.f));
            ly += 40 + 2 * r + 24;
        }
        drawText(res.image, lx, ly, "dark = short: length", 13, Vec3f(0.f));
        drawText(res.image, lx, ly + 18, num(lo) + " .. " + num(hi), 13, Vec3f(0.f));
        drawText(res.image, lx, ly + 36, "grey = inactive", 13, Vec3f(0.f));
        if (res.streamlinesDrawn) drawText(res.image, lx, ly + 54, std::to_string(res.streamlinesDrawn) + " streamlines", 13, Vec3f(0.f));
    } else {
        const int barH = std::max(60, std::min(plot.plotH - 120, 300));
        drawColorBar(res.image, lx, ly + 20, 22, barH, lo, hi, valueType + " value");
        drawText(res.image, lx, ly + 20 + barH + 24, "range " + num(lo) + " .. " + num(hi), 13, Vec3f(0.f));
        drawText(res.image, lx, ly + 20 + barH + 42, "grey = inactive", 13, Vec3f(0.f));
    }
}

} // namespace

const ParamTable<SliceParams>& sliceParameters()
{
    using P = SliceParams;
    static const ParamTable<P> table = [] {
        ParamTable<P> t;
        t.push_back(makeParam<P>("hsv", "Colour vectors by in-plane angle (hue) instead of by their absolute x, y and z (RGB)", "",
                                 ParamAccess<P, bool>{[](const P& p) { return p.color == SliceColor::Hsv; },
                                                      [](P& p, bool hsv) { p.color = hsv ? SliceColor::Hsv : SliceColor::Rgb; }}));
        auto streamlines = makeParam<P>("streamlines", "Overlay this many streamlines of the in-plane field", "",
                                        member<P>([](P& p) -> int& { return p.streamlines; }));
        streamlines.min = 0;
        streamlines.max = SliceParams::kMaxStreamlines;
        t.push_back(streamlines);
        auto width = makeParam<P>("width", "Width of the slice's plot (its height follows the grid's aspect)", "pixels",
                                  member<P>([](P& p) -> int& { return p.width; }));
        width.min = SliceParams::kMinWidth;
        width.max = SliceParams::kMaxWidth;
        t.push_back(width);
        return t;
    }();
    return table;
}

std::string chooseSliceGrid(const std::vector<GridReport>& reports, const std::string& grid, const std::string& path)
{
    if (!grid.empty()) return grid;
    // 'tangent' (what `vdbhair field` writes), else the first grid of voxels.
    for (const GridReport& r : reports) if (r.info.name == "tangent") return r.info.name;
    for (const GridReport& r : reports) if (!r.info.isPoints) return r.info.name;
    throw ValueError(path + ": has no voxel grid to slice (only points)");
}

void parseSlice(const std::string& text, int& axis, double& world)
{
    const ParamError<ValueError> rule({kSliceName, " " + text + ": expected AXIS=WORLD with AXIS x, y or z and WORLD a finite number (e.g. z=1.5)"});
    if (text.size() < 3 || text[1] != '=' || (text[0] != 'x' && text[0] != 'y' && text[0] != 'z')) throw rule;
    axis = text[0] - 'x';
    const std::string number = text.substr(2);
    char* end = nullptr;
    world = std::strtod(number.c_str(), &end);
    if (end == number.c_str() || *end != '\0' || !std::isfinite(world)) throw rule;
}

const ParamTable<InspectParams>& inspectParameters()
{
    using P = InspectParams;
    static const ParamTable<P> table = [] {
        ParamTable<P> t;
        auto grid = makeParam<P>("grid", "Only this grid, and the one sliced (default: every grid; the slice shows 'tangent', else the first voxel grid)",
                                 "", member<P>([](P& p) -> std::string& { return p.grid; }));
        grid.pythonNone = true;
        t.push_back(grid);
        auto slice = makeParam<P>("slice", "Draw the slice AXIS=WORLD (z=1.5: the plane z = 1.5 in world units) into the image", "",
                                  member<P>([](P& p) -> std::string& { return p.slice; }));
        slice.pythonNone = true;
        t.push_back(slice);
        for (Param<P>& q : nestedParams<P>(sliceParameters(), [](P& p) -> SliceParams& { return p.draw; })) t.push_back(std::move(q));
        return t;
    }();
    return table;
}

SliceParams inspectSlice(const InspectParams& p, const std::string& output, const std::string& where)
{
    const std::string prefix = where.empty() ? std::string() : where + ": ";
    const ParamName image{"-o", "output"};
    const auto& table = inspectParameters();
    SliceParams sp = p.draw;
    if (p.slice.empty()) {
        if (!output.empty()) throw ParamError<ValueError>({prefix, image, " " + output + ": an image is drawn only of a slice: add ", kSliceName, " AXIS=WORLD"});
        if (sp.color == SliceColor::Hsv || sp.streamlines) {
            throw ParamError<ValueError>({prefix, paramName(table, "hsv"), " and ", paramName(table, "streamlines"), " draw on a slice: add ", kSliceName,
                                          " AXIS=WORLD and ", image});
        }
        return sp;
    }
    if (output.empty()) throw ParamError<ValueError>({prefix, kSliceName, " " + p.slice + ": needs ", image, ", the slice image's path (.png, .exr, .jpg)"});
    try {
        parseSlice(p.slice, sp.axis, sp.world);
    } catch (const ParamError<ValueError>& e) {
        ParamText text{prefix};
        text += e.text();
        throw ParamError<ValueError>(text);
    }
    if (!isImagePath(output)) {
        throw ParamError<ValueError>({prefix, image, " " + output + ": not an image format OpenImageIO writes (use .png, .exr or .jpg)"});
    }
    return sp;
}

SliceResult renderSlice(const std::string& path, const std::string& gridName, const SliceParams& params)
{
    const std::string where = "inspect(" + path + ")";
    checkSliceParams(params, where);
    const openvdb::GridBase::Ptr base = readVdbGrid(path, gridName, where);
    const std::string gw = where + ": grid '" + gridName + "'";
    const Sampled s = samplerOf(*base, gw);
    const openvdb::CoordBBox ibox = base->evalActiveVoxelBoundingBox();
    if (ibox.empty()) throw ValueError(gw + " has no active voxels to slice");
    const openvdb::BBoxd wbox = worldBoundsOf(ibox, base->transform());
    const int axis = params.axis;
    if (!(params.world >= wbox.min()[axis] && params.world <= wbox.max()[axis])) {
        throw ParamError<ValueError>({gw + ": ", kSliceName, " " + std::string(axisName(axis)) + "=" + num(params.world) + " is outside its active voxels, which span " +
                                                               axisName(axis) + " from " + num(wbox.min()[axis]) + " to " + num(wbox.max()[axis])});
    }
    const SlicePlot plot(axis, params.world, params.width, wbox);
    SliceResult res;
    res.image = Image(plot.imgW, plot.imgH, Vec3f(1.f));
    res.indexPlane = int(std::lround(base->transform().worldToIndex(plot.worldAt(0.5 * plot.plotW, 0.5 * plot.plotH))[axis]));

    const PixelSamples ps = samplePixels(plot, s);
    res.activeVoxels = activeVoxelsOfLayer(*base, ibox, axis, res.indexPlane);
    res.lo = ps.lo;
    res.hi = ps.hi;
    const double ref = s.vector ? (ps.hi > 0.0 ? ps.hi : 1.0) : 0.0;  // the length shown brightest
    paintPixels(res.image, plot, ps, s, params.color, ref);
    if (params.streamlines > 0 && s.vector) {
        res.streamlinesDrawn = drawStreamlines(res.image, plot, ps, s, base->transform().voxelSize(), params.streamlines, ref);
    }
    drawTitleAndLegend(res, plot, s, params.color, gridName, base->valueType());
    return res;
}

} // namespace vdbhair
