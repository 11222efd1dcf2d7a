#include "StrandSamples.h"

#include <vdbhair/Memory.h>

#include <vdbhair/Exceptions.h>
#include <vdbhair/strands/Resample.h>

#include <tbb/parallel_for.h>

#include <string>

namespace vdbhair {

void StrandSamples::push(const float* localRow, const Vec3d& root, const Vec3d& scalpCoord, const ScalpFrame& frame,
                         float length)
{
    local.insert(local.end(), localRow, localRow + dim());
    roots.push_back(root);
    scalp.push_back(scalpCoord);
    frames.push_back(frame);
    lengths.push_back(length);
}

StrandSamples sampleStrands(const StrandSet& strands, const ScalpMap& map, int vertices, bool threaded,
                            const std::vector<std::uint32_t>* order)
{
    if (vertices < 2)
        throw ValueError("sampleStrands: " + std::to_string(vertices) + " vertices per strand: at least 2 are needed");
    const std::size_t n = order ? order->size() : strands.numStrands();
    if (order)
        for (std::uint32_t s : *order)
            if (s >= strands.numStrands())
                throw ValueError("sampleStrands: order names strand " + std::to_string(s) + " of " +
                                 std::to_string(strands.numStrands()) + ": each must be less than the strand count");
    for (std::size_t s = 0; s < strands.numStrands(); ++s)
        if (strands.size(s) < 2)
            throw ValueError("sampleStrands: strand " + std::to_string(s) + " has " + std::to_string(strands.size(s)) +
                             " vertex: at least 2 are needed to resample it");
    StrandSamples out;
    out.vertices = vertices;
    reserveHugePages(out.local, n * out.dim());  // fresh pages 2 MiB at a time (Memory.h)
    out.local.assign(n * out.dim(), 0.0f);
    out.roots.resize(n);
    out.scalp.resize(n);
    out.frames.resize(n);
    out.lengths.resize(n);
    const double inv = 1.0 / map.radius();
    const auto body = [&](const tbb::blocked_range<std::size_t>& r) {
        std::vector<Vec3f> pts(vertices);
        for (std::size_t s = r.begin(); s != r.end(); ++s) {
            const std::size_t from = order ? std::size_t((*order)[s]) : s;
            const Vec3f* p = strands.data(from);
            const std::size_t m = strands.size(from);
            double len = 0.0;
            for (std::size_t i = 1; i < m; ++i) len += (p[i] - p[i - 1]).length();
            resamplePolyline(p, m, std::size_t(vertices), pts.data());
            const Vec3d root(p[0]);
            const Vec3d sc = map.toScalp(root);
            const ScalpFrame f = map.frame(sc.x(), sc.y());
            float* row = out.row(s);
            for (int l = 0; l < vertices; ++l) {
                const Vec3d q = f.toLocal((Vec3d(pts[l]) - root) * inv);
                row[3 * l + 0] = float(q.x());
                row[3 * l + 1] = float(q.y());
                row[3 * l + 2] = float(q.z());
            }
            out.roots[s] = root;
            out.scalp[s] = sc;
            out.frames[s] = f;
            out.lengths[s] = float(len);
        }
    };
    if (threaded) tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 256), body);
    else body(tbb::blocked_range<std::size_t>(0, n));
    return out;
}

// An AVX2 clone and a baseline one: the eight partial sums are one AVX2 register or two SSE ones,
// the same operations on each (AVX2 brings no fused multiply-add), so the same result on any
// machine. (Clustering and detail transfer call it some hundred million times a synthesis.)
__attribute__((target_clones("avx2", "default")))
double sampleDistance2(const float* a, const float* b, std::size_t dim)
{
    // Eight partial sums in a fixed order (the compiler vectorizes them; the result is the same on
    // any thread), then the tail.
    float part[8] = {0.f, 0.f, 0.f, 0.f, 0.f, 0.f, 0.f, 0.f};
    std::size_t i = 0;
    for (; i + 8 <= dim; i += 8)
        for (int k = 0; k < 8; ++k) {
            const float d = a[i + std::size_t(k)] - b[i + std::size_t(k)];
            part[k] += d * d;
        }
    float sum = ((part[0] + part[1]) + (part[2] + part[3])) + ((part[4] + part[5]) + (part[6] + part[7]));
    for (; i < dim; ++i) {
        const float d = a[i] - b[i];
        sum += d * d;
    }
    return double(sum);
}

void sampleToWorld(const float* localRow, int vertices, const Vec3d& root, const ScalpFrame& frame, double radius,
                   Vec3f* out)
{
    for (int l = 0; l < vertices; ++l) {
        const Vec3d q(localRow[3 * l], localRow[3 * l + 1], localRow[3 * l + 2]);
        out[l] = Vec3f(root + frame.toWorld(q) * radius);
    }
}

StrandSet samplesToStrands(const StrandSamples& samples, double radius, bool threaded)
{
    StrandSet out;
    const std::size_t n = samples.count(), ns = std::size_t(samples.vertices);
    if (n * ns >= (std::size_t(1) << 32))
        throw LimitError("samplesToStrands: " + std::to_string(n) + " strands of " + std::to_string(ns) +
                         " vertices exceed the 2^32 vertices a strand set holds");
    reserveHugePages(out.positions, n * ns);  // fresh pages 2 MiB at a time (Memory.h)
    out.positions.resize(n * ns);
    out.offsets.resize(n + 1);
    for (std::size_t s = 0; s <= n; ++s) out.offsets[s] = std::uint32_t(s * ns);
    // Each strand writes only its own vertices: the same on any thread count.
    const auto body = [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t s = r.begin(); s != r.end(); ++s)
            sampleToWorld(samples.row(s), samples.vertices, samples.roots[s], samples.frames[s], radius,
                          out.positions.data() + s * ns);
    };
    if (threaded) tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 256), body);
    else body(tbb::blocked_range<std::size_t>(0, n));
    return out;
}

} // namespace vdbhair
