#include "StrandStats.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/Parallel.h>
#include <vdbhair/Quantile.h>

#include <algorithm>
#include <cmath>
#include <string>

namespace vdbhair {

namespace {

constexpr double kPi = 3.14159265358979323846;

Histogram makeHistogram(const std::vector<double>& values, double lo, double hi, std::size_t bins)
{
    Histogram h;
    h.lo = lo;
    h.hi = hi;
    h.counts.assign(bins, 0);
    const double width = (hi - lo) / double(bins);
    for (double v : values) {
        if (v > hi) {
            ++h.above;
            continue;
        }
        std::size_t b = width > 0.0 ? std::size_t(std::max(0.0, (v - lo) / width)) : 0;
        h.counts[std::min(b, bins - 1)] += 1;
    }
    return h;
}

RangeStats rangeOf(const std::vector<double>& values)
{
    RangeStats r;
    if (values.empty()) return r;
    r.min = *std::min_element(values.begin(), values.end());
    r.max = *std::max_element(values.begin(), values.end());
    double sum = 0.0;
    for (double v : values) sum += v;
    r.mean = sum / double(values.size());
    return r;
}

} // namespace

std::size_t Histogram::total() const
{
    std::size_t t = above;
    for (std::size_t c : counts) t += c;
    return t;
}

double totalTurning(const Vec3f* points, std::size_t n)
{
    double turning = 0.0;
    Vec3d prev(0.0);
    bool havePrev = false;
    for (std::size_t i = 1; i < n; ++i) {
        const Vec3d d(double(points[i].x()) - points[i - 1].x(), double(points[i].y()) - points[i - 1].y(),
                      double(points[i].z()) - points[i - 1].z());
        const double len = d.length();
        if (len == 0.0) continue;
        const Vec3d u = d / len;
        if (havePrev) turning += std::atan2(prev.cross(u).length(), prev.dot(u));  // accurate at small angles
        prev = u;
        havePrev = true;
    }
    return turning;
}

const ParamTable<StrandStatsParams>& strandStatsParameters()
{
    using P = StrandStatsParams;
    static const ParamTable<P> table = [] {
        ParamTable<P> t;
        auto bins = makeParam<P>("bins", "Bins of each histogram (strand length, turning, curvature, vertices per strand)", "",
                                 member<P>([](P& p) -> std::size_t& { return p.bins; }));
        bins.min = 1;
        bins.max = double(StrandStatsParams::kMaxBins);
        t.push_back(bins);
        return t;
    }();
    return table;
}

StrandStatistics computeStrandStatistics(const StrandSet& strands, std::size_t bins, bool threaded)
{
    StrandStatsParams params;
    params.bins = bins;
    checkParams(strandStatsParameters(), params, ParamSpelling::Keyword, "computeStrandStatistics");
    StrandStatistics s;
    s.summary = summarizeStrands(strands);
    const std::size_t n = strands.numStrands();
    std::vector<double> lengths(n), turning(n), counts(n), curvature(strands.numVertices());
    std::vector<float> kappa(strands.numVertices());
    forEachIndex(n, threaded, [&](std::size_t i) {
        lengths[i] = polylineLength(strands.data(i), strands.size(i));
        turning[i] = totalTurning(strands.data(i), strands.size(i)) * 180.0 / kPi;
        counts[i] = double(strands.size(i));
        curvatureProfile(strands.data(i), strands.size(i), kappa.data() + strands.begin(i));
    });
    for (std::size_t v = 0; v < kappa.size(); ++v) curvature[v] = kappa[v];
    s.turning = rangeOf(turning);
    s.curvature = rangeOf(curvature);
    if (!curvature.empty()) s.curvatureP99 = lowerQuantile(curvature, 0.99);
    const RangeStats len = rangeOf(lengths), cnt = rangeOf(counts);
    s.length = makeHistogram(lengths, len.min, len.max, bins);
    s.turningHist = makeHistogram(turning, s.turning.min, s.turning.max, bins);
    s.curvatureHist = makeHistogram(curvature, 0.0, s.curvatureP99, bins);
    s.verticesPerStrand = makeHistogram(counts, cnt.min, cnt.max, bins);
    return s;
}

} // namespace vdbhair
