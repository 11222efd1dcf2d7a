#include "SliceRenderer.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/field/Streamline.h>
#include <vdbhair/io/VdbFile.h>

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

} // namespace

void parseSlice(const std::string& text, int& axis, double& world)
{
    const std::string rule = "slice " + text + ": expected AXIS=WORLD with AXIS x, y or z and WORLD a finite number (e.g. z=1.5)";
    if (text.size() < 3 || text[1] != '=' || (text[0] != 'x' && text[0] != 'y' && text[0] != 'z')) throw ValueError(rule);
    axis = text[0] - 'x';
    const std::string number = text.substr(2);
    char* end = nullptr;
    world = std::strtod(number.c_str(), &end);
    if (end == number.c_str() || *end != '\0' || !std::isfinite(world)) throw ValueError(rule);
}

SliceResult renderSlice(const std::string& path, const std::string& gridName, const SliceParams& params)
{
    const std::string where = "inspect(" + path + ")";
    if (params.axis < 0 || params.axis > 2) throw ValueError(where + ": slice axis " + std::to_string(params.axis) + " is not 0, 1 or 2");
    if (params.width < SliceParams::kMinWidth || params.width > SliceParams::kMaxWidth) {
        throw ValueError(where + ": width " + std::to_string(params.width) + " must be between " + std::to_string(SliceParams::kMinWidth) +
                         " and " + std::to_string(SliceParams::kMaxWidth) + " pixels");
    }
    if (params.streamlines < 0 || params.streamlines > SliceParams::kMaxStreamlines) {
        throw ValueError(where + ": streamlines " + std::to_string(params.streamlines) + " must be between 0 and " +
                         std::to_string(SliceParams::kMaxStreamlines));
    }
    const openvdb::GridBase::Ptr base = readVdbGrid(path, gridName, where);
    const std::string gw = where + ": grid '" + gridName + "'";
    if (base->isType<openvdb::points::PointDataGrid>()) {
        throw ValueError(gw + " holds points; slices show voxel grids (render the strands with 'vdbhair render')");
    }
    Sampled s;
    using namespace openvdb;
    const bool vec = base->apply<TypeList<Vec3SGrid, Vec3DGrid>>([&](const auto& g) { s = makeVectorSampler(g); });
    const bool sca = !vec && base->apply<TypeList<FloatGrid, DoubleGrid, Int32Grid, Int64Grid, BoolGrid>>(
                                 [&](const auto& g) { s = makeScalarSampler(g); });
    if (!vec && !sca) throw ValueError(gw + " holds " + base->valueType() + " values; slices show float, double, int, bool and vec3 grids");
    const CoordBBox ibox = base->evalActiveVoxelBoundingBox();
    if (ibox.empty()) throw ValueError(gw + " has no active voxels to slice");
    const math::Transform& xf = base->transform();
    // World bounds of the active voxels (voxel extents), from the 8 corners of the index box.
    BBoxd wbox;
    for (int c = 0; c < 8; ++c) {
        const Vec3d corner((c & 1 ? ibox.max().x() + 0.5 : ibox.min().x() - 0.5), (c & 2 ? ibox.max().y() + 0.5 : ibox.min().y() - 0.5),
                           (c & 4 ? ibox.max().z() + 0.5 : ibox.min().z() - 0.5));
        wbox.expand(xf.indexToWorld(corner));
    }
    const int axis = params.axis;
    if (!(params.world >= wbox.min()[axis] && params.world <= wbox.max()[axis])) {
        throw ValueError(gw + ": slice " + axisName(axis) + "=" + num(params.world) + " is outside its active voxels, which span " +
                         axisName(axis) + " from " + num(wbox.min()[axis]) + " to " + num(wbox.max()[axis]));
    }
    const PlaneAxes pa = planeAxes(axis);
    const double uLo = pa.uSign > 0 ? wbox.min()[pa.uAxis] : -wbox.max()[pa.uAxis];
    const double uHi = pa.uSign > 0 ? wbox.max()[pa.uAxis] : -wbox.min()[pa.uAxis];
    const double vLo = pa.vSign > 0 ? wbox.min()[pa.vAxis] : -wbox.max()[pa.vAxis];
    const double vHi = pa.vSign > 0 ? wbox.max()[pa.vAxis] : -wbox.min()[pa.vAxis];
    const int plotW = params.width;
    const double scale = double(plotW) / (uHi - uLo);  // pixels per world unit
    const int plotH = std::max(16, std::min(16384, int(std::lround((vHi - vLo) * scale))));
    const int margin = 12, header = 34, panel = 190;
    const int imgW = margin + plotW + panel, imgH = header + std::max(plotH, 400) + margin;  // room for the legend
    SliceResult res;
    res.image = Image(imgW, imgH, Vec3f(1.f));
    const int x0 = margin, y0 = header;
    auto worldAt = [&](double px, double py) {  // plot pixel coordinates (continuous) to world
        Vec3d w(0.0);
        w[axis] = params.world;
        w[pa.uAxis] = pa.uSign * (uLo + px / scale);
        w[pa.vAxis] = pa.vSign * (vHi - py / scale);
        return w;
    };
    auto pixelAt = [&](const Vec3d& w, double& px, double& py) {
        px = (pa.uSign * w[pa.uAxis] - uLo) * scale;
        py = (vHi - pa.vSign * w[pa.vAxis]) * scale;
    };
    res.indexPlane = int(std::lround(xf.worldToIndex(worldAt(0.5 * plotW, 0.5 * plotH))[axis]));

    // Sample every pixel once (nearest voxel).
    std::vector<Vec3d> values(std::size_t(plotW) * std::size_t(plotH));
    std::vector<unsigned char> active(values.size(), 0);
    double lo = std::numeric_limits<double>::max(), hi = -std::numeric_limits<double>::max();
    for (int py = 0; py < plotH; ++py) {
        for (int px = 0; px < plotW; ++px) {
            const std::size_t i = std::size_t(py) * std::size_t(plotW) + std::size_t(px);
            Vec3d v;
            if (!s.nearest(worldAt(px + 0.5, py + 0.5), v)) continue;
            active[i] = 1;
            values[i] = v;
            const double q = s.vector ? v.length() : v.x();
            if (std::isfinite(q)) { lo = std::min(lo, q); hi = std::max(hi, q); }
        }
    }
    // Active voxels of the layer (counted in index space, not pixels).
    {
        std::size_t n = 0;
        CoordBBox layer = ibox;
        if (xf.isLinear()) {
            Coord a = layer.min(), b = layer.max();
            a[axis] = b[axis] = res.indexPlane;
            layer = CoordBBox(a, b);
            base->apply<TypeList<Vec3SGrid, Vec3DGrid, FloatGrid, DoubleGrid, Int32Grid, Int64Grid, BoolGrid>>([&](const auto& g) {
                auto acc = g.getConstAccessor();
                for (auto ijk = layer.begin(); ijk; ++ijk) n += acc.isValueOn(*ijk) ? 1 : 0;
            });
        }
        res.activeVoxels = n;
    }
    if (!(hi >= lo)) { lo = hi = 0.0; }
    res.lo = lo;
    res.hi = hi;
    const Vec3f inactive(0.80f);
    const double ref = s.vector ? (hi > 0.0 ? hi : 1.0) : 0.0;
    for (int py = 0; py < plotH; ++py) {
        for (int px = 0; px < plotW; ++px) {
            const std::size_t i = std::size_t(py) * std::size_t(plotW) + std::size_t(px);
            Vec3f c = inactive;
            if (active[i]) {
                const Vec3d& v = values[i];
                if (s.vector) {
                    const double len = v.length();
                    const double bright = len > 0.0 ? std::min(1.0, len / ref) : 0.0;
                    if (params.color == SliceColor::Rgb) {
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
            res.image.set(x0 + px, y0 + py, c);
        }
    }

    // Streamlines of the in-plane projection, seeded evenly over the active pixels: the
    // streamline engine's midpoint rule at its default step (of the smallest voxel side), both
    // ways from each seed, stopping where a step's stages reverse (a sink, or a sign flip).
    if (params.streamlines > 0 && s.vector) {
        std::vector<std::size_t> on;
        for (std::size_t i = 0; i < active.size(); ++i) if (active[i]) on.push_back(i);
        const Vec3d vs = xf.voxelSize();
        StreamlineRules rules;
        rules.integrator = Integrator::RK2;
        rules.reversal = StageReversal::Stop;
        rules.step = kDefaultStepVoxels * std::min(vs.x(), std::min(vs.y(), vs.z()));
        rules.maxSteps = std::size_t(std::max(0.0, std::min(1e6, 4.0 * ((uHi - uLo) + (vHi - vLo)) / rules.step)));
        const double length = double(rules.maxSteps + 1) * rules.step;  // the step cap ends every streamline
        InPlaneSampler forward{s, axis, 1e-6 * ref};
        ReversedSampler<InPlaneSampler> backward(forward);
        const int n = rules.maxSteps ? std::min<int>(params.streamlines, int(on.size())) : 0;
        std::vector<Vec3d> half;
        for (int k = 0; k < n; ++k) {
            const std::size_t i = on[std::size_t((double(k) + 0.5) * double(on.size()) / double(n))];
            const Vec3d seed = worldAt(double(i % std::size_t(plotW)) + 0.5, double(i / std::size_t(plotW)) + 0.5);
            traceStreamline(backward, seed, length, rules, half);
            std::vector<Vec3d> line(half.rbegin(), half.rend());
            traceStreamline(forward, seed, length, rules, half);
            line.insert(line.end(), half.begin() + 1, half.end());
            if (line.size() < 2) continue;
            ++res.streamlinesDrawn;
            for (int pass = 0; pass < 2; ++pass) {
                const double hw = pass == 0 ? 1.4 : 0.6;
                const Vec3f col = pass == 0 ? Vec3f(0.f) : Vec3f(1.f);
                const float alpha = pass == 0 ? 0.55f : 0.95f;
                for (std::size_t j = 0; j + 1 < line.size(); ++j) {
                    double ax, ay, bx, by;
                    pixelAt(line[j], ax, ay);
                    pixelAt(line[j + 1], bx, by);
                    drawLine(res.image, x0 + ax, y0 + ay, x0 + bx, y0 + by, hw, col, alpha, x0, y0, x0 + plotW, y0 + plotH);
                }
            }
        }
    }

    // Title, axes and legend.
    const char* uName = axisName(pa.uAxis);
    const char* vName = axisName(pa.vAxis);
    drawText(res.image, margin, 22,
             "grid '" + gridName + "'  " + axisName(axis) + " = " + num(params.world) + "  (voxel layer " + std::to_string(res.indexPlane) +
                 ", " + std::to_string(res.activeVoxels) + " active)",
             16, Vec3f(0.f));
    const int lx = x0 + plotW + 16;
    int ly = y0 + 14;
    drawText(res.image, lx, ly, std::string("right: ") + (pa.uSign < 0 ? "-" : "+") + uName, 13, Vec3f(0.f));
    drawText(res.image, lx, ly + 18, std::string("up: ") + (pa.vSign < 0 ? "-" : "+") + vName, 13, Vec3f(0.f));
    drawText(res.image, lx, ly + 36, "pixel: " + num(1.0 / scale) + " units", 13, Vec3f(0.f));
    ly += 70;
    if (s.vector) {
        if (params.color == SliceColor::Rgb) {
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
                    if (d > r || cx + x >= imgW || cy + y >= imgH) continue;
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
        const int barH = std::max(60, std::min(plotH - 120, 300));
        drawColorBar(res.image, lx, ly + 20, 22, barH, lo, hi, base->valueType() + " value");
        drawText(res.image, lx, ly + 20 + barH + 24, "range " + num(lo) + " .. " + num(hi), 13, Vec3f(0.f));
        drawText(res.image, lx, ly + 20 + barH + 42, "grey = inactive", 13, Vec3f(0.f));
    }
    return res;
}

} // namespace vdbhair
