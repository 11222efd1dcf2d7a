#include "Measures.h"
#include "Summary.h"

#include <vdbhair/Exceptions.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <cmath>
#include <string>

namespace vdbhair {

namespace {

inline Vec3d toD(const Vec3f& v) { return Vec3d(v.x(), v.y(), v.z()); }

/// Tangent of the circle through a (before), 0 (the vertex) and b (after), given as offsets
/// from the vertex: |a|² b - |b|² a is perpendicular to the circle's radius at 0 and points
/// towards b (see Measures.h). Degenerates to the chord direction when a point repeats.
Vec3d circleTangent(const Vec3d& a, const Vec3d& b)
{
    const double aa = a.lengthSqr(), bb = b.lengthSqr();
    if (aa == 0.0) return b;
    if (bb == 0.0) return -a;
    return aa * b - bb * a;
}

template<typename Fn>
void forEachStrand(const StrandSet& strands, Fn&& fn)
{
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, strands.numStrands(), 64),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                          for (std::size_t i = r.begin(); i != r.end(); ++i) fn(i);
                      });
}

} // namespace

double polylineLength(const Vec3f* points, std::size_t n)
{
    double len = 0.0;
    for (std::size_t i = 1; i < n; ++i) len += (toD(points[i]) - toD(points[i - 1])).length();
    return len;
}

void arcLengths(const Vec3f* points, std::size_t n, double* out)
{
    if (n == 0) return;
    out[0] = 0.0;
    for (std::size_t i = 1; i < n; ++i) {
        out[i] = out[i - 1] + (toD(points[i]) - toD(points[i - 1])).length();
    }
}

std::vector<float> strandLengths(const StrandSet& strands)
{
    std::vector<float> out(strands.numStrands());
    forEachStrand(strands, [&](std::size_t i) {
        out[i] = float(polylineLength(strands.data(i), strands.size(i)));
    });
    return out;
}

void computeTangents(const Vec3f* points, std::size_t n, Vec3f* out)
{
    if (n == 0) return;
    if (n == 1) { out[0] = Vec3f(0.f); return; }
    // Index of the nearest point distinct from point i, searching backwards / forwards.
    auto prevDistinct = [&](std::size_t i) -> std::ptrdiff_t {
        for (std::ptrdiff_t j = std::ptrdiff_t(i) - 1; j >= 0; --j) {
            if (points[j] != points[i]) return j;
        }
        return -1;
    };
    auto nextDistinct = [&](std::size_t i) -> std::ptrdiff_t {
        for (std::size_t j = i + 1; j < n; ++j) {
            if (points[j] != points[i]) return std::ptrdiff_t(j);
        }
        return -1;
    };
    for (std::size_t i = 0; i < n; ++i) {
        const std::ptrdiff_t ip = prevDistinct(i), in = nextDistinct(i);
        const Vec3d p = toD(points[i]);
        Vec3d t(0.0);
        if (ip >= 0 && in >= 0) {
            t = circleTangent(toD(points[ip]) - p, toD(points[in]) - p);
        } else if (in >= 0) {
            // Root: tangent at p of the circle through p, the next and the one after.
            const std::ptrdiff_t in2 = nextDistinct(std::size_t(in));
            const Vec3d a = toD(points[in]) - p;
            t = (in2 >= 0) ? -circleTangent(a, toD(points[in2]) - p) : a;
            if (t.dot(a) <= 0.0) t = a;  // collinear fold-back: keep the chord
        } else if (ip >= 0) {
            const std::ptrdiff_t ip2 = prevDistinct(std::size_t(ip));
            const Vec3d a = p - toD(points[ip]);
            t = (ip2 >= 0) ? circleTangent(-a, toD(points[ip2]) - p) : a;
            if (t.dot(a) <= 0.0) t = a;
        }
        const double len = t.length();
        out[i] = len > 0.0 ? Vec3f(float(t.x() / len), float(t.y() / len), float(t.z() / len))
                           : Vec3f(0.f);
    }
}

std::vector<Vec3f> computeTangents(const StrandSet& strands)
{
    std::vector<Vec3f> out(strands.numVertices());
    forEachStrand(strands, [&](std::size_t i) {
        computeTangents(strands.data(i), strands.size(i), out.data() + strands.begin(i));
    });
    return out;
}

void curvatureProfile(const Vec3f* points, std::size_t n, float* out)
{
    if (n == 0) return;
    if (n < 3) { std::fill(out, out + n, 0.f); return; }
    for (std::size_t i = 1; i + 1 < n; ++i) {
        const Vec3d a = toD(points[i]) - toD(points[i - 1]);
        const Vec3d b = toD(points[i + 1]) - toD(points[i]);
        const double denom = a.length() * b.length() * (a + b).length();
        out[i] = denom > 0.0 ? float(2.0 * a.cross(b).length() / denom) : 0.f;
    }
    out[0] = out[1];
    out[n - 1] = out[n - 2];
}

void torsionProfile(const Vec3f* points, std::size_t n, float* out)
{
    if (n == 0) return;
    if (n < 4) { std::fill(out, out + n, 0.f); return; }
    // Discrete binormal at interior vertex i: unit (e_{i-1} x e_i); zero where straight.
    std::vector<Vec3d> binormal(n, Vec3d(0.0));
    for (std::size_t i = 1; i + 1 < n; ++i) {
        const Vec3d a = toD(points[i]) - toD(points[i - 1]);
        const Vec3d b = toD(points[i + 1]) - toD(points[i]);
        const Vec3d c = a.cross(b);
        const double len = c.length();
        if (len > 1e-12 * a.length() * b.length() && len > 0.0) binormal[i] = c / len;
    }
    // Edge i joins vertices i and i+1 (interior edges only: 1 .. n-3).
    std::vector<double> edgeTorsion(n - 1, 0.0);
    for (std::size_t i = 1; i + 2 < n; ++i) {
        const Vec3d& b0 = binormal[i];
        const Vec3d& b1 = binormal[i + 1];
        const Vec3d e = toD(points[i + 1]) - toD(points[i]);
        const double len = e.length();
        if (b0.lengthSqr() == 0.0 || b1.lengthSqr() == 0.0 || len == 0.0) continue;
        const double angle = std::atan2(b0.cross(b1).dot(e / len), b0.dot(b1));
        edgeTorsion[i] = angle / len;
    }
    for (std::size_t i = 2; i + 2 < n; ++i) {
        out[i] = float(0.5 * (edgeTorsion[i - 1] + edgeTorsion[i]));
    }
    out[1] = float(edgeTorsion[1]);
    out[n - 2] = float(edgeTorsion[n - 3]);
    out[0] = out[1];
    out[n - 1] = out[n - 2];
}

StrandSummary summarizeStrands(const StrandSet& strands)
{
    std::vector<std::uint32_t> counts(strands.numStrands());
    for (std::size_t i = 0; i < counts.size(); ++i) counts[i] = std::uint32_t(strands.size(i));
    StrandSummary s = summarizeStrands(strands.numVertices(), computeBBox(strands), strandLengths(strands), counts);
    s.metersPerUnit = strands.metersPerUnit;
    s.upAxis = strands.upAxis;
    return s;
}

StrandSummary summarizeStrands(std::size_t vertices, const BBox& bbox, const std::vector<float>& lengths,
                               const std::vector<std::uint32_t>& vertexCounts)
{
    StrandSummary s;
    s.strands = lengths.size();
    s.vertices = vertices;
    s.bbox = bbox;
    if (s.strands == 0) return s;
    s.length.min = s.verticesPerStrand.min = std::numeric_limits<double>::max();
    s.length.max = s.verticesPerStrand.max = -std::numeric_limits<double>::max();
    double lenSum = 0.0;
    for (std::size_t i = 0; i < s.strands; ++i) {  // fixed order: deterministic sums
        const double len = lengths[i], nv = double(vertexCounts[i]);
        lenSum += len;
        s.length.min = std::min(s.length.min, len);
        s.length.max = std::max(s.length.max, len);
        s.verticesPerStrand.min = std::min(s.verticesPerStrand.min, nv);
        s.verticesPerStrand.max = std::max(s.verticesPerStrand.max, nv);
    }
    s.length.mean = lenSum / double(s.strands);
    s.verticesPerStrand.mean = double(s.vertices) / double(s.strands);
    return s;
}

} // namespace vdbhair

namespace vdbhair {

namespace {
/// Spread the low 10 bits of @a v to every third bit.
std::uint32_t spreadBits(std::uint32_t v)
{
    v &= 0x3ff;
    v = (v | (v << 16)) & 0x030000ff;
    v = (v | (v << 8)) & 0x0300f00f;
    v = (v | (v << 4)) & 0x030c30c3;
    v = (v | (v << 2)) & 0x09249249;
    return v;
}
} // namespace

namespace {
/// The Morton order of @a n points given by @a point(i) (see spatialOrder()).
/// The box of the @a n points @a point(i), in parallel in ranges of @a grain (a min and a max: the
/// same box for any split; non-finite coordinates are left out, as BBox::expand() does).
template<typename PointFn>
BBox boxOf(std::size_t n, PointFn&& point, std::size_t grain)
{
    return tbb::parallel_reduce(
        tbb::blocked_range<std::size_t>(0, n, grain), BBox(),
        [&](const tbb::blocked_range<std::size_t>& r, BBox b) {
            for (std::size_t i = r.begin(); i != r.end(); ++i) b.expand(point(i));
            return b;
        },
        [](BBox a, const BBox& b) {
            if (!b.empty()) {
                a.expand(b.min);
                a.expand(b.max);
            }
            return a;
        });
}

/// In parallel above a few thousand points (each point's read is a cache miss when the points are
/// a strand set's roots): the box is a min and max, and the keys are unique (they hold the index),
/// so the result is the same for any thread count.
template<typename PointFn>
std::vector<std::uint32_t> mortonOrder(std::size_t n, PointFn&& point)
{
    constexpr std::size_t kGrain = 4096;
    const BBox box = boxOf(n, point, kGrain);
    const Vec3f e = box.extent();
    std::vector<std::uint64_t> keys(n);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, kGrain), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
            const Vec3f p = point(i);
            std::uint32_t code = 0;
            for (int k = 0; k < 3; ++k) {
                const float f = e[k] > 0.f ? (p[k] - box.min[k]) / e[k] : 0.f;
                const std::uint32_t q = std::uint32_t(std::min(1023.f, std::max(0.f, f * 1024.f)));
                code |= spreadBits(q) << k;
            }
            keys[i] = (std::uint64_t(code) << 32) | std::uint64_t(i);
        }
    });
    if (n > kGrain) tbb::parallel_sort(keys.begin(), keys.end());
    else std::sort(keys.begin(), keys.end());
    std::vector<std::uint32_t> order(n);
    for (std::size_t i = 0; i < n; ++i) order[i] = std::uint32_t(keys[i] & 0xffffffffu);
    return order;
}
} // namespace

/// (Declared in StrandSet.h; here beside spatialOrder(), with the box's one parallel reduction.)
BBox computeBBox(const StrandSet& strands)
{
    const std::vector<Vec3f>& v = strands.positions;
    return boxOf(v.size(), [&](std::size_t i) { return v[i]; }, std::size_t(1) << 16);
}

std::vector<std::uint32_t> spatialOrder(const StrandSet& strands)
{
    return mortonOrder(strands.numStrands(), [&](std::size_t i) { return strands.root(i); });
}

std::vector<std::uint32_t> spatialOrder(const std::vector<Vec3d>& points)
{
    return mortonOrder(points.size(), [&](std::size_t i) { return Vec3f(points[i]); });
}

double meanVertexDisplacement(const StrandSet& a, const StrandSet& b, bool threaded)
{
    if (a.numStrands() != b.numStrands()) {
        throw ValueError("meanVertexDisplacement: " + std::to_string(a.numStrands()) + " strands against " +
                         std::to_string(b.numStrands()) + "; the sets must correspond strand by strand");
    }
    const std::size_t nS = a.numStrands();
    std::vector<double> sum(nS, 0.0);
    std::vector<std::size_t> count(nS, 0);
    auto body = [&](const tbb::blocked_range<std::size_t>& r) {
        std::vector<double> sa, sb;
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
            const std::size_t na = a.size(i), nb = b.size(i);
            sa.resize(na);
            sb.resize(nb);
            arcLengths(a.data(i), na, sa.data());
            arcLengths(b.data(i), nb, sb.data());
            const Vec3f* pa = a.data(i);
            const Vec3f* pb = b.data(i);
            // The strand's sum in a register (the same additions in the same order): through
            // sum[i], each addition waited for the last one's store.
            double total = 0.0;
            std::size_t k = 0, j = 0;
            const double end = sb[nb - 1] + 1e-6 * std::max(1.0, sb[nb - 1]);
            for (; k < na; ++k) {
                const double s = sa[k];
                if (s > end) break;
                while (j + 2 < nb && sb[j + 1] < s) ++j;
                const double len = sb[j + 1] - sb[j];
                const double f = len > 0.0 ? std::min(1.0, std::max(0.0, (s - sb[j]) / len)) : 0.0;
                const Vec3d q = toD(pb[j]) + f * (toD(pb[j + 1]) - toD(pb[j]));
                total += (toD(pa[k]) - q).length();
            }
            sum[i] = total;
            count[i] = k;
        }
    };
    if (threaded) tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nS, 64), body);
    else body(tbb::blocked_range<std::size_t>(0, nS));
    double total = 0.0;
    std::size_t n = 0;
    for (std::size_t i = 0; i < nS; ++i) { total += sum[i]; n += count[i]; }
    return n ? total / double(n) : 0.0;
}

} // namespace vdbhair
