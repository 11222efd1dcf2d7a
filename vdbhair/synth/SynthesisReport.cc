#include "SynthesisReport.h"

#include <vdbhair/Quantile.h>
#include <vdbhair/helicoid/Frechet.h>
#include <vdbhair/strands/PointCloud.h>
#include <vdbhair/strands/Measures.h>
#include <vdbhair/strands/Resample.h>

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace vdbhair {

double relativeWasserstein(std::vector<double> a, std::vector<double> b)
{
    if (a.empty() || b.empty()) return a.empty() && b.empty() ? 0.0 : std::numeric_limits<double>::infinity();
    std::sort(a.begin(), a.end());
    std::sort(b.begin(), b.end());
    // W1 = ∫ |F_a⁻¹(q) − F_b⁻¹(q)| dq, summed over the merged quantile breakpoints.
    double w = 0.0, q = 0.0;
    std::size_t i = 0, j = 0;
    const double na = double(a.size()), nb = double(b.size());
    while (i < a.size() && j < b.size()) {
        const double qa = double(i + 1) / na, qb = double(j + 1) / nb, next = std::min(qa, qb);
        w += (next - q) * std::abs(a[i] - b[j]);
        q = next;
        if (qa <= next) ++i;
        if (qb <= next) ++j;
    }
    double mean = 0.0;
    for (double x : a) mean += x;
    mean /= na;
    return mean > 0.0 ? w / mean : w;
}

std::vector<double> turningPerLength(const StrandSet& strands)
{
    std::vector<double> out(strands.numStrands(), 0.0);
    for (std::size_t s = 0; s < strands.numStrands(); ++s) {
        const Vec3f* p = strands.data(s);
        const std::size_t n = strands.size(s);
        double len = 0.0, turn = 0.0;
        for (std::size_t i = 1; i < n; ++i) {
            const Vec3d e(p[i] - p[i - 1]);
            len += e.length();
            if (i + 1 < n) {
                const Vec3d f(p[i + 1] - p[i]);
                const double c = e.dot(f) / std::max(1e-30, e.length() * f.length());
                turn += std::acos(std::clamp(c, -1.0, 1.0));
            }
        }
        out[s] = len > 0.0 ? turn / len : 0.0;
    }
    return out;
}

double meanTurningPerLength(const StrandSet& strands, int vertices)
{
    if (strands.empty()) return 0.0;
    const std::vector<double> t = turningPerLength(resampleStrands(strands, std::size_t(vertices)));
    double sum = 0.0;
    for (double x : t) sum += x;
    return sum / double(t.size());
}

double meanTurningPerLengthAtSpacing(const StrandSet& strands, double spacing)
{
    if (strands.empty()) return 0.0;
    const std::vector<double> t = turningPerLength(resampleStrandsBySpacing(strands, float(spacing)));
    double sum = 0.0;
    for (double x : t) sum += x;
    return sum / double(t.size());
}

std::vector<double> clusterMeanDeviation(const StrandSet& a, const std::vector<std::int32_t>& labelA, const StrandSet& b,
                                         const std::vector<std::int32_t>& labelB, int vertices, double smoothing)
{
    std::int32_t K = 0;
    for (std::int32_t l : labelA) K = std::max(K, l + 1);
    for (std::int32_t l : labelB) K = std::max(K, l + 1);
    const std::size_t m = std::size_t(std::max(2, vertices));
    const auto means = [&](const StrandSet& set, const std::vector<std::int32_t>& label) {
        std::vector<std::vector<Vec3d>> mean(std::size_t(K), std::vector<Vec3d>(m, Vec3d(0.0)));
        std::vector<std::size_t> count(std::size_t(K), 0);
        std::vector<Vec3f> pts(m);
        for (std::size_t s = 0; s < set.numStrands() && s < label.size(); ++s) {
            if (label[s] < 0 || set.size(s) < 2) continue;
            resamplePolyline(set.data(s), set.size(s), m, pts.data());
            for (std::size_t v = 0; v < m; ++v) mean[std::size_t(label[s])][v] += Vec3d(pts[v]);
            ++count[std::size_t(label[s])];
        }
        std::vector<Vec3d> tmp(m);
        for (std::size_t c = 0; c < mean.size(); ++c) {
            for (Vec3d& p : mean[c]) p /= double(std::max<std::size_t>(1, count[c]));
            smoothPolyline(mean[c].data(), m, smoothing * double(m), tmp.data());
            mean[c].swap(tmp);
        }
        return std::make_pair(mean, count);
    };
    const auto [ma, ca] = means(a, labelA);
    const auto [mb, cb] = means(b, labelB);
    std::vector<double> out;
    for (std::size_t c = 0; c < std::size_t(K); ++c) {
        if (!ca[c] || !cb[c]) continue;
        double len = 0.0;
        for (std::size_t v = 1; v < m; ++v) len += (mb[c][v] - mb[c][v - 1]).length();
        out.push_back(discreteFrechet(ma[c].data(), m, mb[c].data(), m) / std::max(1e-30, len));
    }
    return out;
}

NoveltyStats measureNovelty(const StrandSet& example, const StrandSet& output, double radius, int vertices, bool threaded)
{
    NoveltyStats st;
    if (example.numStrands() < 2 || output.empty()) return st;
    const StrandSet ex = resampleStrands(example, std::size_t(vertices)), out = resampleStrands(output, std::size_t(vertices));
    std::vector<Vec3d> roots(ex.numStrands());
    for (std::size_t s = 0; s < roots.size(); ++s) roots[s] = Vec3d(ex.root(s));
    PointCloud cloud{&roots};
    PointKdTree tree(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(16));
    tree.buildIndex();
    const auto nearest = [&](const StrandSet& set, std::size_t s, bool skipSelf) {
        constexpr std::size_t K = 9;
        std::uint32_t idx[K];
        double d2[K];
        const Vec3f r = set.root(s);
        const double q[3] = {r.x(), r.y(), r.z()};
        const std::size_t got = tree.knnSearch(q, std::min(K, roots.size()), idx, d2);
        double best = std::numeric_limits<double>::max();
        for (std::size_t j = 0; j < got; ++j) {
            if (skipSelf && idx[j] == s) continue;
            double sum = 0.0;
            for (int v = 0; v < vertices; ++v) sum += (Vec3d(set.data(s)[v]) - Vec3d(ex.data(idx[j])[v])).lengthSqr();
            best = std::min(best, std::sqrt(sum / vertices) / radius);
        }
        return best;
    };
    const auto run = [&](const StrandSet& set, bool skipSelf) {
        std::vector<double> d(set.numStrands());
        const auto body = [&](const tbb::blocked_range<std::size_t>& r) {
            for (std::size_t s = r.begin(); s != r.end(); ++s) d[s] = nearest(set, s, skipSelf);
        };
        if (threaded) tbb::parallel_for(tbb::blocked_range<std::size_t>(0, d.size(), 256), body);
        else body(tbb::blocked_range<std::size_t>(0, d.size()));
        return d;
    };
    std::vector<double> a = run(out, false), b = run(ex, true);
    std::size_t copies = 0;
    for (double x : a) copies += x < 0.01;
    st.copies = double(copies) / double(a.size());
    st.outputMedian = upperMedian(std::move(a));
    st.exampleMedian = upperMedian(std::move(b));
    return st;
}

std::vector<double> clusterSizes(const std::vector<std::int32_t>& label)
{
    std::int32_t k = 0;
    for (std::int32_t l : label) k = std::max(k, l + 1);
    std::vector<double> size(std::size_t(k), 0.0);
    for (std::int32_t l : label) size[std::size_t(l)] += 1.0;
    size.erase(std::remove(size.begin(), size.end(), 0.0), size.end());
    return size;
}

} // namespace vdbhair
