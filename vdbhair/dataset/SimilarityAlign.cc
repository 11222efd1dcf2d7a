#include "SimilarityAlign.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/Format.h>
#include <vdbhair/Parallel.h>
#include <vdbhair/Quantile.h>
#include <vdbhair/dataset/Prepare.h>
#include <vdbhair/strands/PointCloud.h>

#include <openvdb/math/Proximity.h>

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

/// @a m indices of [0, n) evenly spaced (all of them when m >= n).
std::vector<std::uint32_t> evenIndices(std::size_t n, std::size_t m)
{
    std::vector<std::uint32_t> out;
    const std::size_t k = std::min(n, m);
    out.reserve(k);
    for (std::size_t j = 0; j < k; ++j) out.push_back(std::uint32_t(j * n / k));
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
/// A result keeps up up when the source's up turns to within 30 degrees of the target's. The
/// direction from a head's centroid to its roots' leans back from the vertical by 10-20 degrees
/// on the shared grooms; fits of a rounded head on its side or upside down lean 38 degrees and
/// more (docs/datasets.md).
constexpr double kUprightCosine = 0.866;

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

/// The point of triangle (a, b, c) nearest @a p, as barycentric weights (OpenVDB's
/// closestPointOnTriangleToPoint); a degenerate triangle gives its first corner.
Vec3d closestOnTriangle(const Vec3d& p, const Vec3d& a, const Vec3d& b, const Vec3d& c)
{
    Vec3d uvw(1.0, 0.0, 0.0);
    openvdb::math::closestPointOnTriangleToPoint(a, b, c, p, uvw);
    if (!std::isfinite(uvw.x()) || !std::isfinite(uvw.y()) || !std::isfinite(uvw.z())) return Vec3d(1.0, 0.0, 0.0);
    return uvw;
}

/// A surface to find nearest points on: a mesh's vertices and triangles (or points alone). The
/// nearest point is sought on the triangles around the few vertices nearest the query, which
/// finds it on any mesh whose triangles are not much longer than the distance to it.
class Surface
{
public:
    struct Hit
    {
        std::array<std::uint32_t, 3> corner{0, 0, 0};
        Vec3d weight{1, 0, 0};  ///< barycentric, over corner
        double d2 = 0.0;
    };

    Surface(std::vector<Vec3d> vertices, const std::vector<std::array<std::uint32_t, 3>>& triangles)
        : mTree(std::move(vertices)), mTriangles(&triangles)
    {
        // Each vertex's triangles, as prefix sums.
        mStart.assign(mTree.pts.size() + 1, 0);
        for (const auto& t : triangles) {
            for (std::uint32_t v : t) ++mStart[v + 1];
        }
        for (std::size_t v = 0; v < mTree.pts.size(); ++v) mStart[v + 1] += mStart[v];
        mOf.resize(mStart.back());
        std::vector<std::uint32_t> fill(mStart.begin(), mStart.end() - 1);
        for (std::size_t i = 0; i < triangles.size(); ++i) {
            for (std::uint32_t v : triangles[i]) mOf[fill[v]++] = std::uint32_t(i);
        }
        mScale = rmsRadius(mTree.pts, centroid(mTree.pts));
    }

    const std::vector<Vec3d>& vertices() const { return mTree.pts; }
    /// The RMS radius of the vertices about their centroid: the surface's size.
    double scale() const { return mScale; }

    Hit nearest(const Vec3d& p) const
    {
        constexpr std::size_t kNear = 4;
        const double q[3] = {p.x(), p.y(), p.z()};
        std::uint32_t idx[kNear] = {};
        double dist[kNear] = {};
        const std::size_t found = mTree.index.knnSearch(q, kNear, idx, dist);
        Hit best;
        best.corner = {idx[0], idx[0], idx[0]};
        best.d2 = dist[0];
        const auto& pts = mTree.pts;
        for (std::size_t k = 0; k < found; ++k) {
            for (std::uint32_t e = mStart[idx[k]]; e < mStart[idx[k] + 1]; ++e) {
                const auto& t = (*mTriangles)[mOf[e]];
                const Vec3d w = closestOnTriangle(p, pts[t[0]], pts[t[1]], pts[t[2]]);
                const double d2 = (pts[t[0]] * w.x() + pts[t[1]] * w.y() + pts[t[2]] * w.z() - p).lengthSqr();
                if (d2 < best.d2) {
                    best.d2 = d2;
                    best.corner = t;
                    best.weight = w;
                }
            }
        }
        return best;
    }

    /// The unit normal of the triangle of @a h over @a pts, or zero for a vertex alone (points
    /// without triangles, or a degenerate triangle).
    static Vec3d normal(const Hit& h, const std::vector<Vec3d>& pts)
    {
        if (h.corner[0] == h.corner[1] && h.corner[1] == h.corner[2]) return Vec3d(0.0);
        const Vec3d n = (pts[h.corner[1]] - pts[h.corner[0]]).cross(pts[h.corner[2]] - pts[h.corner[0]]);
        const double len = n.length();
        return len > 0.0 ? n / len : Vec3d(0.0);
    }

    Vec3d point(const Hit& h, const std::vector<Vec3d>& pts) const
    {
        return pts[h.corner[0]] * h.weight.x() + pts[h.corner[1]] * h.weight.y() + pts[h.corner[2]] * h.weight.z();
    }

private:
    Tree mTree;
    const std::vector<std::array<std::uint32_t, 3>>* mTriangles;
    std::vector<std::uint32_t> mStart, mOf;
    double mScale = 0.0;
};

/// A matched pair at the current transform: the moved source point, its target point and the
/// unit normal of the surface the match was found on (zero: match the points themselves).
struct Pair
{
    Vec3d x, q, n;
};

/// One evaluation of trimmed ICP at @a T: the kept pairs of both directions and their RMS distance.
struct IcpStep
{
    std::vector<Pair> pairs;
    double rms = 0.0;
};

/// The two point sets of an alignment: each a surface, and the vertices of it that are matched.
struct Side
{
    const std::vector<Vec3d>* points;
    const std::vector<std::array<std::uint32_t, 3>>* triangles;
    std::vector<std::uint32_t> samples;
};

/// Pair the moved source's samples with their nearest points on the target surface, and the
/// target's samples with their nearest points on the moved source surface; keep the nearest
/// @a overlap share of each direction.
IcpStep pairUp(const Side& source, const Surface& target, const Side& targetSide, const Similarity& T, double overlap, bool threaded)
{
    const std::vector<Vec3d>& src = *source.points;
    std::vector<Vec3d> moved(src.size());
    forEachIndex(src.size(), threaded, [&](std::size_t i) { moved[i] = T.apply(src[i]); }, 1024);
    const std::size_t n = source.samples.size(), m = targetSide.samples.size();
    std::vector<Surface::Hit> fwd(n), rev(m);
    forEachIndex(n, threaded, [&](std::size_t i) { fwd[i] = target.nearest(moved[source.samples[i]]); }, 128);
    const Surface movedSurface(std::move(moved), *source.triangles);
    forEachIndex(m, threaded, [&](std::size_t j) { rev[j] = movedSurface.nearest((*targetSide.points)[targetSide.samples[j]]); }, 128);
    std::vector<double> fwdD2(n), revD2(m);
    for (std::size_t i = 0; i < n; ++i) fwdD2[i] = fwd[i].d2;
    for (std::size_t j = 0; j < m; ++j) revD2[j] = rev[j].d2;
    const double qf = nearestRankQuantile(fwdD2, overlap), qr = nearestRankQuantile(revD2, overlap);
    IcpStep s;
    double sum = 0.0;
    const std::vector<Vec3d>& mv = movedSurface.vertices();
    for (std::size_t i = 0; i < n; ++i) {
        if (fwdD2[i] > qf) continue;
        s.pairs.push_back({mv[source.samples[i]], target.point(fwd[i], target.vertices()), Surface::normal(fwd[i], target.vertices())});
        sum += fwdD2[i];
    }
    for (std::size_t j = 0; j < m; ++j) {
        if (revD2[j] > qr) continue;
        s.pairs.push_back({movedSurface.point(rev[j], mv), (*targetSide.points)[targetSide.samples[j]], Surface::normal(rev[j], mv)});
        sum += revD2[j];
    }
    s.rms = s.pairs.empty() ? 0.0 : std::sqrt(sum / double(s.pairs.size()));
    return s;
}

/// One Gauss-Newton step of the similarity that moves the pairs' x onto the planes through q
/// with normals n (point-to-plane ICP, Chen & Medioni 1992, with a scale; point-to-point rows
/// where a pair has no normal), linearized about the x's centroid: x -> c + (1 + sigma)
/// exp([omega]) (x - c) + tau. @return @a T composed with that step, or false when the step is
/// undetermined.
bool planeStep(const std::vector<Pair>& pairs, Similarity& T)
{
    if (pairs.size() < 3) return false;
    Vec3d c(0.0);
    for (const Pair& p : pairs) c += p.x;
    c /= double(pairs.size());
    Eigen::Matrix<double, 7, 7> AtA = Eigen::Matrix<double, 7, 7>::Zero();
    Eigen::Matrix<double, 7, 1> Atb = Eigen::Matrix<double, 7, 1>::Zero();
    auto addRow = [&](const Vec3d& xc, const Vec3d& dir, double residual) {
        const Vec3d r = xc.cross(dir);
        Eigen::Matrix<double, 7, 1> a;
        a << r.x(), r.y(), r.z(), xc.dot(dir), dir.x(), dir.y(), dir.z();
        AtA.noalias() += a * a.transpose();
        Atb.noalias() += a * residual;
    };
    for (const Pair& p : pairs) {
        const Vec3d xc = p.x - c, d = p.x - p.q;
        if (p.n.lengthSqr() > 0.0) {
            addRow(xc, p.n, -d.dot(p.n));
        } else {
            for (int k = 0; k < 3; ++k) {
                Vec3d e(0.0);
                e[k] = 1.0;
                addRow(xc, e, -d[k]);
            }
        }
    }
    // A tiny ridge keeps a symmetric surface's free rotation (a sphere's) at zero instead of undetermined.
    const double ridge = 1e-12 * AtA.trace();
    AtA += ridge * Eigen::Matrix<double, 7, 7>::Identity();
    const Eigen::Matrix<double, 7, 1> u = AtA.ldlt().solve(Atb);
    if (!u.allFinite()) return false;
    const double f = 1.0 + u(3);
    if (!(f > 0.0)) return false;
    // The step's rotation as a matrix, exp([omega]), to compose with T's and re-orthonormalize by
    // SVD (a fit, not a turn of a vector): Rotation.h's rotateByVector() turns vectors only.
    const Eigen::Vector3d omega(u(0), u(1), u(2));
    const double angle = omega.norm();
    const Eigen::Matrix3d Rw = angle > 0.0 ? Eigen::AngleAxisd(angle, omega / angle).toRotationMatrix() : Eigen::Matrix3d::Identity();
    openvdb::math::Mat3d R;
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) R(i, j) = Rw(i, j);
    }
    Similarity step;
    step.scale = f;
    step.rotation = R;
    step.translation = Vec3d(0.0);
    step.translation = c + Vec3d(u(4), u(5), u(6)) - step.apply(c);
    // step after T: x -> step(T(x)).
    Similarity next;
    next.scale = step.scale * T.scale;
    next.rotation = step.rotation * T.rotation;
    next.translation = step.apply(T.translation);
    // Re-orthonormalize the rotation (products of many steps drift).
    Eigen::Matrix3d M;
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) M(i, j) = next.rotation(i, j);
    }
    const Eigen::JacobiSVD<Eigen::Matrix3d> svd(M, Eigen::ComputeFullU | Eigen::ComputeFullV);
    Eigen::Matrix3d Q = svd.matrixU() * svd.matrixV().transpose();
    if (Q.determinant() < 0.0) return false;
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) next.rotation(i, j) = Q(i, j);
    }
    T = next;
    return true;
}

/// Trimmed ICP from @a T for at most @a iterations steps; @a T ends at the lowest RMS met.
/// Trimming makes the RMS not quite monotone (a pair dropped or taken back), so a step that
/// raises it does not stop the iteration; a change below the tolerance does. @return that RMS.
double runIcp(const Side& source, const Surface& target, const Side& targetSide, Similarity& T, int iterations,
              const AlignParams& params, bool threaded, int* done)
{
    IcpStep step = pairUp(source, target, targetSide, T, params.overlap, threaded);
    Similarity current = T;
    double best = step.rms;
    int it = 0;
    for (; it < iterations; ++it) {
        if (!planeStep(step.pairs, current)) break;
        const double previous = step.rms;
        step = pairUp(source, target, targetSide, current, params.overlap, threaded);
        if (!std::isfinite(step.rms)) break;
        if (step.rms < best) {
            best = step.rms;
            T = current;
        }
        // Converged: the change is below the tolerance, or the fit is exact to rounding.
        if (std::abs(previous - step.rms) <= params.tolerance * step.rms || step.rms <= 1e-12 * target.scale()) {
            ++it;
            break;
        }
    }
    if (done) *done = it;
    return best;
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
/// distances from @a T(src) to the surface @a target.
void measureResidual(const std::vector<Vec3d>& src, const Surface& target, const Similarity& T, double overlap, bool threaded,
                     AlignResult& r)
{
    std::vector<double> d2(src.size());
    forEachIndex(src.size(), threaded, [&](std::size_t i) { d2[i] = target.nearest(T.apply(src[i])).d2; }, 128);
    const double q = nearestRankQuantile(d2, overlap);
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

void checkTriangles(const std::vector<std::array<std::uint32_t, 3>>& triangles, std::size_t vertices, const char* name)
{
    for (std::size_t i = 0; i < triangles.size(); ++i) {
        for (std::uint32_t v : triangles[i]) {
            if (v >= vertices) {
                throw ValueError(std::string("alignMeshes: ") + name + " triangle " + std::to_string(i) + " names vertex " + std::to_string(v) +
                                 " of " + std::to_string(vertices));
            }
        }
    }
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
    if (!(c > 0.0) || !std::isfinite(c)) throw ValueError("fitSimilarity: the points determine no scale (scale " + formatNumber(c) + ")");
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
    if (!(overlap > 0.0 && overlap <= 1.0)) {
        throw ParamError<ValueError>({paramName(prepareParameters(), "overlap"), " " + formatNumber(overlap) + ": must be in (0, 1]"});
    }
    if (iterations < 0) throw ValueError("AlignParams::iterations " + std::to_string(iterations) + ": must be 0 or more");
    if (startIterations < 0) throw ValueError("AlignParams::startIterations " + std::to_string(startIterations) + ": must be 0 or more");
    if (startSamples < 3) throw ValueError("AlignParams::startSamples " + std::to_string(startSamples) + ": must be 3 or more");
    if (maxSamples < 3) throw ValueError("AlignParams::maxSamples " + std::to_string(maxSamples) + ": must be 3 or more");
    if (!(tolerance >= 0.0) || !std::isfinite(tolerance)) throw ValueError("AlignParams::tolerance " + formatNumber(tolerance) + ": must be finite and non-negative");
    for (const Vec3d* v : {&sourceUp, &targetUp}) {
        if (!std::isfinite(v->x()) || !std::isfinite(v->y()) || !std::isfinite(v->z())) throw ValueError("AlignParams: an up direction is not finite");
    }
}

const char* alignMethodName(AlignMethod method)
{
    return method == AlignMethod::Correspondence ? "correspondence" : "icp";
}

namespace {

/// Trimmed ICP between two surfaces (triangles may be empty: points alone), from the axis rotations.
AlignResult alignSurfaces(const std::vector<Vec3d>& from, const std::vector<std::array<std::uint32_t, 3>>& fromTriangles,
                          const std::vector<Vec3d>& to, const std::vector<std::array<std::uint32_t, 3>>& toTriangles,
                          const AlignParams& params, bool threaded)
{
    params.validate();
    checkPoints(from, "the source");
    checkPoints(to, "the target");
    const Vec3d cs = centroid(from), ct = centroid(to);
    const double rs = rmsRadius(from, cs), rt = rmsRadius(to, ct);
    if (!(rs > 0.0) || !(rt > 0.0)) throw ValueError("alignPointSets: every point of the " + std::string(rs > 0.0 ? "target" : "source") + " is the same point");
    const Surface target(to, toTriangles);

    // The 24 starts, each matching a subsample, in parallel (each start's own work is serial, so
    // the result is the same on any thread count).
    const std::vector<openvdb::math::Mat3d> rotations = axisRotations();
    const Side srcStart{&from, &fromTriangles, evenIndices(from.size(), params.startSamples)};
    const Side tgtStart{&to, &toTriangles, evenIndices(to.size(), params.startSamples)};
    // Only the starts that keep up up, when the caller says which way is up; and only the
    // results that still do (ICP may slide a rounded head over the other until it is upside down).
    const bool upright = params.sourceUp.lengthSqr() > 0.0 && params.targetUp.lengthSqr() > 0.0;
    auto upCosine = [&](const openvdb::math::Mat3d& rotation) {
        Similarity R;
        R.rotation = rotation;
        return R.apply(params.sourceUp).unit().dot(params.targetUp.unit());
    };
    auto keepsUp = [&](const Similarity& T) { return !upright || upCosine(T.rotation) >= kUprightCosine; };
    std::vector<std::size_t> order;
    for (std::size_t k = 0; k < rotations.size(); ++k) {
        if (!upright || upCosine(rotations[k]) > 0.0) order.push_back(k);
    }
    std::vector<Similarity> starts(rotations.size());
    std::vector<double> score(rotations.size(), std::numeric_limits<double>::infinity());
    forEachIndex(order.size(), threaded, [&](std::size_t o) {
        const std::size_t k = order[o];
        Similarity T;
        T.scale = rt / rs;
        T.rotation = rotations[k];
        T.translation = Vec3d(0.0);
        T.translation = ct - T.apply(cs);
        score[k] = runIcp(srcStart, target, tgtStart, T, params.startIterations, params, false, nullptr);
        starts[k] = T;
    }, 1);
    // Starts that slid out of upright rank after every upright one.
    std::vector<char> upOk(rotations.size(), 1);
    for (std::size_t k : order) upOk[k] = keepsUp(starts[k]);
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
        if (upOk[a] != upOk[b]) return upOk[a] > upOk[b];
        return score[a] < score[b];
    });

    // The best few starts refined on the larger samples (on a subsample two starts can rank the
    // other way round from where they end); the lowest final RMS wins, ties to the better start.
    AlignResult r;
    r.method = AlignMethod::Icp;
    const Side src{&from, &fromTriangles, evenIndices(from.size(), params.maxSamples)};
    const Side tgt{&to, &toTriangles, evenIndices(to.size(), params.maxSamples)};
    double bestRms = std::numeric_limits<double>::infinity();
    bool bestUp = false;
    for (std::size_t c = 0; c < std::min<std::size_t>(order.size(), kRefinedStarts); ++c) {
        Similarity T = starts[order[c]];
        int iterations = 0;
        const double rms = runIcp(src, target, tgt, T, params.iterations, params, threaded, &iterations);
        const bool up = keepsUp(T);
        if ((up && !bestUp) || (up == bestUp && rms < bestRms)) {
            bestUp = up;
            bestRms = rms;
            r.transform = T;
            r.start = int(order[c]);
            r.iterations = iterations;
        }
    }
    measureResidual(from, target, r.transform, params.overlap, threaded, r);
    return r;
}

} // namespace

AlignResult alignPointSets(const std::vector<Vec3d>& from, const std::vector<Vec3d>& to, const AlignParams& params, bool threaded)
{
    return alignSurfaces(from, {}, to, {}, params, threaded);
}

AlignResult alignMeshes(const TriangleMesh& from, const TriangleMesh& to, const AlignParams& params, bool threaded)
{
    params.validate();
    checkTriangles(from.triangles, from.vertices.size(), "the source");
    checkTriangles(to.triangles, to.vertices.size(), "the target");
    const std::vector<Vec3d> src = toD(from.vertices), dst = toD(to.vertices);
    if (from.vertices.size() == to.vertices.size() && from.triangles == to.triangles) {
        // One head model in two places: vertex i is vertex i.
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
    return alignSurfaces(src, from.triangles, dst, to.triangles, params, threaded);
}

} // namespace vdbhair
