#include "Resample.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/Format.h>
#include <vdbhair/Memory.h>
#include <vdbhair/strands/Measures.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

namespace vdbhair {

namespace {

/// For each of @a count equally spaced arc lengths, the segment index and the fraction along it.
void arcParameters(const Vec3f* points, std::size_t n, std::size_t count,
                   std::vector<std::size_t>& seg, std::vector<float>& frac)
{
    std::vector<double> s(n);
    arcLengths(points, n, s.data());
    const double total = s[n - 1];
    seg.resize(count);
    frac.resize(count);
    std::size_t j = 0;
    for (std::size_t k = 0; k < count; ++k) {
        const double target = (k + 1 == count) ? total : total * double(k) / double(count - 1);
        while (j + 2 < n && s[j + 1] < target) ++j;
        const double len = s[j + 1] - s[j];
        double f = len > 0.0 ? (target - s[j]) / len : 0.0;
        if (k + 1 == count) f = (total > 0.0) ? 1.0 : 0.0;
        seg[k] = j;
        frac[k] = float(std::min(1.0, std::max(0.0, f)));
    }
    if (total == 0.0) {  // zero length: every sample is the root
        std::fill(seg.begin(), seg.end(), std::size_t(0));
        std::fill(frac.begin(), frac.end(), 0.f);
    }
}

template<typename T>
T lerp(const T& a, const T& b, float f) { return a + (b - a) * f; }

StrandSet resampleWithCounts(const StrandSet& in, const std::vector<std::uint32_t>& offsets)
{
    StrandSet out;
    out.defaults = in.defaults;
    out.offsets = offsets;
    const std::size_t nV = offsets.back();
    out.positions.resize(nV);
    if (!in.thickness.empty()) out.thickness.resize(nV);
    if (!in.transparency.empty()) out.transparency.resize(nV);
    if (!in.color.empty()) out.color.resize(nV);
    out.rootUV = in.rootUV;
    out.strandId = in.strandId;
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, in.numStrands(), 64),
        [&](const tbb::blocked_range<std::size_t>& r) {
            std::vector<std::size_t> seg;
            std::vector<float> frac;
            for (std::size_t i = r.begin(); i != r.end(); ++i) {
                const std::size_t count = out.size(i), b = in.begin(i), ob = out.begin(i);
                arcParameters(in.data(i), in.size(i), count, seg, frac);
                for (std::size_t k = 0; k < count; ++k) {
                    const std::size_t v0 = b + seg[k], v1 = v0 + 1;
                    const float f = frac[k];
                    out.positions[ob + k] = lerp(in.positions[v0], in.positions[v1], f);
                    if (!in.thickness.empty()) out.thickness[ob + k] = lerp(in.thickness[v0], in.thickness[v1], f);
                    if (!in.transparency.empty()) out.transparency[ob + k] = lerp(in.transparency[v0], in.transparency[v1], f);
                    if (!in.color.empty()) out.color[ob + k] = lerp(in.color[v0], in.color[v1], f);
                }
                out.positions[ob] = in.positions[b];  // the root stays exactly where it was
            }
        });
    return out;
}

} // namespace

void resamplePolyline(const Vec3f* points, std::size_t n, std::size_t count, Vec3f* out)
{
    if (count == 0 || n == 0) return;
    if (n == 1 || count == 1) {
        std::fill(out, out + count, points[0]);
        return;
    }
    std::vector<std::size_t> seg;
    std::vector<float> frac;
    arcParameters(points, n, count, seg, frac);
    for (std::size_t k = 0; k < count; ++k) out[k] = lerp(points[seg[k]], points[seg[k] + 1], frac[k]);
    out[0] = points[0];
}

namespace {

/// The bytes a vertex of @a s takes: its position and the per-vertex attributes it carries.
std::size_t bytesPerVertex(const StrandSet& s)
{
    return sizeof(Vec3f) + (s.thickness.empty() ? 0 : sizeof(float)) + (s.transparency.empty() ? 0 : sizeof(float)) +
           (s.color.empty() ? 0 : sizeof(Vec3f));
}

} // namespace

StrandSet resampleStrands(const StrandSet& strands, std::size_t verticesPerStrand)
{
    if (verticesPerStrand < 2) {
        throw ValueError("resampleStrands: " + std::to_string(verticesPerStrand) +
                         " vertices per strand requested; a strand needs at least 2");
    }
    const double total = double(strands.numStrands()) * double(verticesPerStrand);
    if (total > double(std::numeric_limits<std::uint32_t>::max())) {
        throw ValueError("resampleStrands: " + std::to_string(strands.numStrands()) + " strands x " + std::to_string(verticesPerStrand) +
                         " vertices = " + formatNumber(total) + " vertices: more than a hairstyle holds (2^32-1)");
    }
    checkMemory("resampleStrands", std::uint64_t(total * double(bytesPerVertex(strands))),
                std::to_string(strands.numStrands()) + " strands x " + std::to_string(verticesPerStrand) + " vertices = " + formatNumber(total) +
                    " vertices of " + std::to_string(bytesPerVertex(strands)) + " bytes",
                "fewer vertices per strand");
    std::vector<std::uint32_t> offsets(strands.numStrands() + 1);
    for (std::size_t i = 0; i < offsets.size(); ++i) offsets[i] = std::uint32_t(i * verticesPerStrand);
    return resampleWithCounts(strands, offsets);
}

StrandSet resampleStrandsBySpacing(const StrandSet& strands, float spacing, std::size_t maxVertices)
{
    if (!(spacing > 0.f) || !std::isfinite(spacing)) {
        throw ValueError("resampleStrandsBySpacing: spacing " + std::to_string(spacing) +
                         " must be a positive finite length");
    }
    const std::vector<float> lengths = strandLengths(strands);
    std::vector<std::uint32_t> offsets(strands.numStrands() + 1, 0);
    std::size_t total = 0;
    for (std::size_t i = 0; i < lengths.size(); ++i) {
        const double n = std::max(2.0, std::round(double(lengths[i]) / spacing) + 1.0);
        total += std::size_t(std::min(n, double(maxVertices) + 1.0));
        if (total > maxVertices || total > std::numeric_limits<std::uint32_t>::max()) {
            throw LimitError("resampleStrandsBySpacing: spacing " + std::to_string(spacing) +
                             " would give more than " + std::to_string(maxVertices) + " vertices");
        }
        offsets[i + 1] = std::uint32_t(total);
    }
    return resampleWithCounts(strands, offsets);
}

// An AVX2 clone and a baseline one: the inner loop below runs four points or two at a time, the
// same operations on each (AVX2 brings no fused multiply-add), so the same result on any machine.
__attribute__((target_clones("avx2", "default")))
void smoothPolyline(const Vec3d* points, std::size_t n, double sigma, Vec3d* out)
{
    if (n == 0) return;
    if (!(sigma > 0.0) || n < 3) {
        std::copy(points, points + n, out);
        return;
    }
    const long last = long(n) - 1;
    // Truncated at 3σ, and at the polyline's own length so that one reflection reaches every tap.
    const long radius = std::min(last, std::max(1L, long(std::ceil(3.0 * sigma))));
    std::vector<double> kernel(std::size_t(radius) + 1);
    for (long k = 0; k <= radius; ++k) kernel[std::size_t(k)] = std::exp(-0.5 * double(k * k) / (sigma * sigma));
    // The polyline extended by odd reflection, radius points each side, one array per axis:
    // ext[a][k + radius] is axis a of the point at index k (−radius ≤ k ≤ last + radius). Taps in
    // the outer loop and points in the inner one: every output sums its taps in the same order as
    // one point at a time (bit for bit), and the inner loop runs without branches over
    // consecutive points, which the compiler vectorizes.
    const std::size_t m = n + 2 * std::size_t(radius);
    std::vector<double> buf(3 * m + 3 * n);
    double* ext[3] = {buf.data(), buf.data() + m, buf.data() + 2 * m};
    double* sum[3] = {buf.data() + 3 * m, buf.data() + 3 * m + n, buf.data() + 3 * m + 2 * n};
    for (long k = -radius; k <= last + radius; ++k) {
        Vec3d e;
        if (k < 0) e = points[0] * 2.0 - points[-k];
        else if (k > last) e = points[last] * 2.0 - points[2 * last - k];
        else e = points[k];
        for (int a = 0; a < 3; ++a) ext[a][std::size_t(k + radius)] = e[a];
    }
    double w = kernel[0];
    for (long k = 1; k <= radius; ++k) w += 2.0 * kernel[std::size_t(k)];
    for (int a = 0; a < 3; ++a) {
        const double* c = ext[a] + radius;  // c[i] is axis a of point i
        double* s = sum[a];
        const double k0 = kernel[0];
        for (long i = 1; i < last; ++i) s[i] = c[i] * k0;
        for (long k = 1; k <= radius; ++k) {
            const double kk = kernel[std::size_t(k)];
            const double* lo = c - k;
            const double* hi = c + k;
            for (long i = 1; i < last; ++i) s[i] += (lo[i] + hi[i]) * kk;
        }
    }
    out[0] = points[0];
    out[last] = points[last];
    for (long i = 1; i < last; ++i) out[i] = Vec3d(sum[0][i], sum[1][i], sum[2][i]) / w;
}

} // namespace vdbhair
