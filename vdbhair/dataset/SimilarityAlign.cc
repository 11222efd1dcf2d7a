#include "SimilarityAlign.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/Parallel.h>
#include <vdbhair/strands/PointCloud.h>

#include <Eigen/Dense>
#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <string>

namespace vdbhair {

namespace {

std::string num(double v)
{
    char buf[64];
    std::snprintf(buf, sizeof buf, "%g", v);
    return buf;
}

/// A k-d tree over its own copy of points.
struct Tree
{
    std::vector<Vec3d> pts;
    PointCloud cloud{&pts};
    PointKdTree index;

    explicit Tree(std::vector<Vec3d> p)
        : pts(std::move(p)), index(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(10))
    {
        index.buildIndex();
    }
    Tree(const Tree&) = delete;
    Tree& operator=(const Tree&) = delete;

    /// The nearest point's index and squared distance.
    std::pair<std::uint32_t, double> nearest(const Vec3d& p) const
    {
        const double q[3] = {p.x(), p.y(), p.z()};
        std::uint32_t i = 0;
        double d2 = 0.0;
        index.knnSearch(q, 1, &i, &d2);
        return {i, d2};
    }
};

/// @a m points of @a pts evenly by index (all of them when m >= size).
std::vector<Vec3d> evenSample(const std::vector<Vec3d>& pts, std::size_t m)
{
    if (m >= pts.size()) return pts;
    std::vector<Vec3d> out(m);
    for (std::size_t k = 0; k < m; ++k) out[k] = pts[k * pts.size() / m];
    return out;
}

Vec3d centroid(const std::vector<Vec3d>& pts)
{
    Vec3d c(0.0);
    for (const Vec3d& p : pts) c += p;
    return c / double(pts.size());
}

double rmsRadius(const std::vector<Vec3d>& pts, const Vec3d& c)
{
    double s = 0.0;
    for (const Vec3d& p : pts) s += (p - c).lengthSqr();
    return std::sqrt(s / double(pts.size()));
}

/// How many of the best starts are refined on the larger samples.
constexpr std::size_t kRefinedStarts = 3;

/// The 24 proper rotations that map coordinate axes to coordinate axes (the cube's rotations).
std::vector<openvdb::math::Mat3d> axisRotations()
{
    std::vector<openvdb::math::Mat3d> out;
    std::array<int, 3> perm{0, 1, 2};
    do {
        for (int signs = 0; signs < 8; ++signs) {
            openvdb::math::Mat3d m = openvdb::math::Mat3d::zero();
            for (int r = 0; r < 3; ++r) m(r, perm[r]) = (signs >> r) & 1 ? -1.0 : 1.0;
            if (m.det() > 0.0) out.push_back(m);
        }
    } while (std::next_permutation(perm.begin(), perm.end()));
    return out;
}

/// The value at share @a q (0..1] of @a d2 in increasing order.
double quantile(std::vector<double> d2, double q)
{
    if (d2.empty()) return 0.0;
    const std::size_t k = std::min(d2.size() - 1, std::size_t(std::ceil(q * double(d2.size()))) - (q > 0.0 ? 1 : 0));
    std::nth_element(d2.begin(), d2.begin() + std::ptrdiff_t(k), d2.end());
    return d2[k];
}

/// One evaluation of trimmed ICP at @a T: the kept pairs of both directions and their RMS.
struct IcpStep
{
    std::vector<Vec3d> from, to;
    double rms = 0.0;
};

/// @param matched how many of @a target's first points are matched back to the source (the
/// others, triangle centroids, are targets of the source's points only: as sources of pairs they
/// would pull the source towards the middle of triangles it has no vertex in)
IcpStep pairUp(const std::vector<Vec3d>& src, const Tree& target, std::size_t matched, const Similarity& T, double overlap, bool threaded)
{
    const std::size_t n = src.size(), m = matched;
    std::vector<Vec3d> moved(n);
    forEachIndex(n, threaded, [&](std::size_t i) { moved[i] = T.apply(src[i]); }, 1024);
    std::vector<std::uint32_t> fwd(n), rev(m);
    std::vector<double> fwdD2(n), revD2(m);
    forEachIndex(n, threaded, [&](std::size_t i) { std::tie(fwd[i], fwdD2[i]) = target.nearest(moved[i]); }, 256);
    const Tree movedTree(std::move(moved));
    forEachIndex(m, threaded, [&](std::size_t j) { std::tie(rev[j], revD2[j]) = movedTree.nearest(target.pts[j]); }, 256);
    const double qf = quantile(fwdD2, overlap), qr = quantile(revD2, overlap);
    IcpStep s;
    double sum = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
        if (fwdD2[i] > qf) continue;
        s.from.push_back(src[i]);
        s.to.push_back(target.pts[fwd[i]]);
        sum += fwdD2[i];
    }
    for (std::size_t j = 0; j < m; ++j) {
        if (revD2[j] > qr) continue;
        s.from.push_back(src[rev[j]]);
        s.to.push_back(target.pts[j]);
        sum += revD2[j];
    }
    s.rms = s.from.empty() ? 0.0 : std::sqrt(sum / double(s.from.size()));
    return s;
}

/// Trimmed ICP from @a T for at most @a iterations updates; @return the RMS at the final @a T.
double runIcp(const std::vector<Vec3d>& src, const Tree& target, std::size_t matched, Similarity& T, int iterations,
              const AlignParams& params, bool threaded, int* done)
{
    IcpStep step = pairUp(src, target, matched, T, params.overlap, threaded);
    int it = 0;
    for (; it < iterations; ++it) {
        Similarity next;
        try {
            next = fitSimilarity(step.from, step.to);
        } catch (const ValueError&) {
            break;  // the kept pairs collapsed to a point: keep the last transform
        }
        IcpStep nextStep = pairUp(src, target, matched, next, params.overlap, threaded);
        if (!(nextStep.rms <= step.rms)) break;  // no longer improving (or not finite)
        const double change = step.rms - nextStep.rms;
        T = next;
        step = std::move(nextStep);
        if (change <= params.tolerance * step.rms) {
            ++it;
            break;
        }
    }
    if (done) *done = it;
    return step.rms;
}

void checkPoints(const std::vector<Vec3d>& pts, const char* name)
{
    if (pts.size() < 3) throw ValueError(std::string("alignPointSets: ") + name + " has " + std::to_string(pts.size()) + " points; at least 3 are needed");
    for (std::size_t i = 0; i < pts.size(); ++i) {
        const Vec3d& p = pts[i];
        if (!std::isfinite(p.x()) || !std::isfinite(p.y()) || !std::isfinite(p.z())) {
            throw ValueError(std::string("alignPointSets: ") + name + " point " + std::to_string(i) + " is not finite");
        }
    }
}

/// RMS over the nearest @a overlap share, the largest of those, and the RMS over all, of the
/// distances from @a T(src) to @a target.
void measureResidual(const std::vector<Vec3d>& src, const Tree& target, const Similarity& T, double overlap, bool threaded,
                     AlignResult& r)
{
    std::vector<double> d2(src.size());
    forEachIndex(src.size(), threaded, [&](std::size_t i) { d2[i] = target.nearest(T.apply(src[i])).second; }, 256);
    const double q = quantile(d2, overlap);
    double kept = 0.0, all = 0.0, mx = 0.0;
    std::size_t nKept = 0;
    for (double v : d2) {
        all += v;
        if (v <= q) {
            kept += v;
            ++nKept;
            mx = std::max(mx, v);
        }
    }
    r.rms = nKept ? std::sqrt(kept / double(nKept)) : 0.0;
    r.max = std::sqrt(mx);
    r.rmsAll = d2.empty() ? 0.0 : std::sqrt(all / double(d2.size()));
    r.pairs = src.size();
}

std::vector<Vec3d> toD(const std::vector<Vec3f>& v)
{
    std::vector<Vec3d> out(v.size());
    for (std::size_t i = 0; i < v.size(); ++i) out[i] = Vec3d(v[i].x(), v[i].y(), v[i].z());
    return out;
}

} // namespace

Vec3d Similarity::apply(const Vec3d& p) const
{
    const openvdb::math::Mat3d& R = rotation;
    return Vec3d(scale * (R(0, 0) * p.x() + R(0, 1) * p.y() + R(0, 2) * p.z()) + translation.x(),
                 scale * (R(1, 0) * p.x() + R(1, 1) * p.y() + R(1, 2) * p.z()) + translation.y(),
                 scale * (R(2, 0) * p.x() + R(2, 1) * p.y() + R(2, 2) * p.z()) + translation.z());
}

Similarity Similarity::inverse() const
{
    Similarity inv;
    inv.scale = 1.0 / scale;
    inv.rotation = rotation.transpose();
    inv.translation = Vec3d(0.0);
    inv.translation = -inv.apply(translation);
    return inv;
}

Similarity fitSimilarity(const std::vector<Vec3d>& from, const std::vector<Vec3d>& to)
{
    if (from.size() != to.size()) {
        throw ValueError("fitSimilarity: " + std::to_string(from.size()) + " points to map onto " + std::to_string(to.size()) + "; the counts must agree");
    }
    if (from.size() < 3) throw ValueError("fitSimilarity: " + std::to_string(from.size()) + " point pairs; at least 3 are needed");
    Eigen::Matrix3Xd src(3, from.size()), dst(3, to.size());
    for (std::size_t i = 0; i < from.size(); ++i) {
        src.col(Eigen::Index(i)) << from[i].x(), from[i].y(), from[i].z();
        dst.col(Eigen::Index(i)) << to[i].x(), to[i].y(), to[i].z();
    }
    const Eigen::Vector3d mean = src.rowwise().mean();
    if ((src.colwise() - mean).squaredNorm() <= 0.0) throw ValueError("fitSimilarity: every point to map is the same point; no scale or rotation is determined");
    // Umeyama (1991), Eq. 40-42: returns [cR t; 0 1].
    const Eigen::Matrix4d m = Eigen::umeyama(src, dst, true);
    const Eigen::Matrix3d cR = m.topLeftCorner<3, 3>();
    const double c = std::cbrt(cR.determinant());
    if (!(c > 0.0) || !std::isfinite(c)) throw ValueError("fitSimilarity: the points determine no scale (scale " + num(c) + ")");
    Similarity s;
    s.scale = c;
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) s.rotation(i, j) = cR(i, j) / c;
    }
    s.translation = Vec3d(m(0, 3), m(1, 3), m(2, 3));
    return s;
}

void AlignParams::validate() const
{
    if (!(overlap > 0.0 && overlap <= 1.0)) throw ValueError("AlignParams::overlap " + num(overlap) + ": must be in (0, 1]");
    if (iterations < 0) throw ValueError("AlignParams::iterations " + std::to_string(iterations) + ": must be 0 or more");
    if (startIterations < 0) throw ValueError("AlignParams::startIterations " + std::to_string(startIterations) + ": must be 0 or more");
    if (startSamples < 3) throw ValueError("AlignParams::startSamples " + std::to_string(startSamples) + ": must be 3 or more");
    if (maxSamples < 3) throw ValueError("AlignParams::maxSamples " + std::to_string(maxSamples) + ": must be 3 or more");
    if (!(tolerance >= 0.0) || !std::isfinite(tolerance)) throw ValueError("AlignParams::tolerance " + num(tolerance) + ": must be finite and non-negative");
    for (const Vec3d* v : {&sourceUp, &targetUp}) {
        if (!std::isfinite(v->x()) || !std::isfinite(v->y()) || !std::isfinite(v->z())) throw ValueError("AlignParams: an up direction is not finite");
    }
}

const char* alignMethodName(AlignMethod method)
{
    return method == AlignMethod::Correspondence ? "correspondence" : "icp";
}

namespace {

/// @a a then @a b.
std::vector<Vec3d> joined(std::vector<Vec3d> a, const std::vector<Vec3d>& b)
{
    a.insert(a.end(), b.begin(), b.end());
    return a;
}

AlignResult alignPointSetsImpl(const std::vector<Vec3d>& from, const std::vector<Vec3d>& to, const std::vector<Vec3d>& toExtra,
                               const AlignParams& params, bool threaded)
{
    params.validate();
    checkPoints(from, "the source");
    checkPoints(to, "the target");
    const Vec3d cs = centroid(from), ct = centroid(to);
    const double rs = rmsRadius(from, cs), rt = rmsRadius(to, ct);
    if (!(rs > 0.0) || !(rt > 0.0)) throw ValueError("alignPointSets: every point of the " + std::string(rs > 0.0 ? "target" : "source") + " is the same point");

    // The 24 starts, each on a subsample, in parallel (each start's own work is serial, so the
    // result is the same on any thread count); the lowest RMS wins, ties to the lower start.
    const std::vector<openvdb::math::Mat3d> rotations = axisRotations();
    const std::vector<Vec3d> srcStart = evenSample(from, params.startSamples);
    const std::vector<Vec3d> toStart = evenSample(to, params.startSamples);
    const Tree targetStart(joined(toStart, evenSample(toExtra, params.startSamples)));
    std::vector<Similarity> starts(rotations.size());
    std::vector<double> score(rotations.size());
    forEachIndex(rotations.size(), threaded, [&](std::size_t k) {
        Similarity T;
        T.scale = rt / rs;
        T.rotation = rotations[k];
        T.translation = Vec3d(0.0);
        T.translation = ct - T.apply(cs);
        score[k] = runIcp(srcStart, targetStart, toStart.size(), T, params.startIterations, params, false, nullptr);
        starts[k] = T;
    }, 1);
    // Only the starts that keep up up, when the caller says which way is up.
    const bool upright = params.sourceUp.lengthSqr() > 0.0 && params.targetUp.lengthSqr() > 0.0;
    auto allowed = [&](std::size_t k) {
        if (!upright) return true;
        Similarity R;
        R.rotation = rotations[k];
        return R.apply(params.sourceUp).dot(params.targetUp) > 0.0;
    };
    std::vector<std::size_t> order;
    for (std::size_t k = 0; k < starts.size(); ++k) {
        if (allowed(k)) order.push_back(k);
    }
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return score[a] < score[b]; });

    // The best few starts refined on the larger samples (on a subsample two starts can rank the
    // other way round from where they end); the lowest final RMS wins, ties to the better start.
    AlignResult r;
    r.method = AlignMethod::Icp;
    const std::vector<Vec3d> src = evenSample(from, params.maxSamples);
    const std::vector<Vec3d> toRefine = evenSample(to, params.maxSamples);
    const Tree target(joined(toRefine, evenSample(toExtra, params.maxSamples)));
    double bestRms = std::numeric_limits<double>::infinity();
    for (std::size_t c = 0; c < std::min<std::size_t>(order.size(), kRefinedStarts); ++c) {
        Similarity T = starts[order[c]];
        int iterations = 0;
        const double rms = runIcp(src, target, toRefine.size(), T, params.iterations, params, threaded, &iterations);
        if (rms < bestRms) {
            bestRms = rms;
            r.transform = T;
            r.start = int(order[c]);
            r.iterations = iterations;
        }
    }
    const Tree fullTarget(joined(to, toExtra));
    measureResidual(from, fullTarget, r.transform, params.overlap, threaded, r);
    return r;
}

} // namespace

AlignResult alignPointSets(const std::vector<Vec3d>& from, const std::vector<Vec3d>& to, const AlignParams& params, bool threaded)
{
    return alignPointSetsImpl(from, to, {}, params, threaded);
}

AlignResult alignMeshes(const TriangleMesh& from, const TriangleMesh& to, const AlignParams& params, bool threaded)
{
    params.validate();
    const std::vector<Vec3d> src = toD(from.vertices);
    if (from.vertices.size() == to.vertices.size() && from.triangles == to.triangles) {
        // One head model in two places: vertex i is vertex i.
        const std::vector<Vec3d> dst = toD(to.vertices);
        AlignResult r;
        r.method = AlignMethod::Correspondence;
        r.transform = fitSimilarity(src, dst);
        std::vector<double> d2(src.size());
        forEachIndex(src.size(), threaded, [&](std::size_t i) { d2[i] = (r.transform.apply(src[i]) - dst[i]).lengthSqr(); }, 1024);
        double sum = 0.0, mx = 0.0;
        for (double v : d2) {
            sum += v;
            mx = std::max(mx, v);
        }
        r.rms = r.rmsAll = std::sqrt(sum / double(d2.size()));
        r.max = std::sqrt(mx);
        r.pairs = src.size();
        return r;
    }
    // The target surface: its vertices, and its triangles' centroids as targets of the source's points.
    std::vector<Vec3d> centroids;
    centroids.reserve(to.triangles.size());
    for (const auto& t : to.triangles) {
        centroids.push_back((Vec3d(to.vertices[t[0]]) + Vec3d(to.vertices[t[1]]) + Vec3d(to.vertices[t[2]])) / 3.0);
    }
    return alignPointSetsImpl(src, toD(to.vertices), centroids, params, threaded);
}

} // namespace vdbhair
