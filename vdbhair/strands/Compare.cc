#include "Compare.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/strands/PointCloud.h>
#include <vdbhair/strands/Resample.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <unordered_set>
#include <cmath>
#include <string>

namespace vdbhair {

namespace {

/// The oriented points of a hairstyle: each segment's start, its unit direction and its strand.
struct OrientedPoints
{
    std::vector<Vec3d> position;
    std::vector<Vec3d> direction;
    std::vector<std::uint32_t> strand;
};

OrientedPoints orientedPoints(const StrandSet& s)
{
    OrientedPoints o;
    for (std::size_t i = 0; i < s.numStrands(); ++i) {
        const Vec3f* p = s.positions.data() + s.begin(i);
        for (std::size_t k = 0; k + 1 < s.size(i); ++k) {
            const Vec3d a(p[k].x(), p[k].y(), p[k].z()), b(p[k + 1].x(), p[k + 1].y(), p[k + 1].z());
            const Vec3d d = b - a;
            const double l = d.length();
            if (!(l > 0.0)) continue;  // a repeated vertex has no direction
            o.position.push_back(a);
            o.direction.push_back(d / l);
            o.strand.push_back(std::uint32_t(i));
        }
    }
    return o;
}

/// nanoflann's result set for one oriented point: each point within the largest threshold distance
/// is tested against every threshold at once, as the tree finds it. Without @a hits it stops the
/// search as soon as every threshold has a match (all precision and recall need); with them it
/// records each (threshold, strand) match for the strand consistency.
struct MatchVisitor
{
    const OrientedPoints& to;
    const std::vector<OrientedThreshold>& thresholds;
    const std::vector<double>& cosines;
    bool bidirectional;
    double radius2;
    Vec3d direction;
    std::uint32_t matched = 0, all = 0;
    std::vector<std::uint64_t>* hits = nullptr;  ///< threshold << 32 | strand of @a to

    bool addPoint(double d2, std::uint32_t index)
    {
        double c = direction.dot(to.direction[index]);
        if (bidirectional) c = std::abs(c);
        for (std::size_t t = 0; t < thresholds.size(); ++t) {
            if (d2 > thresholds[t].distance * thresholds[t].distance || c < cosines[t]) continue;
            matched |= 1u << t;
            if (hits) hits->push_back(std::uint64_t(t) << 32 | to.strand[index]);
        }
        return hits != nullptr || matched != all;
    }
    double worstDist() const { return radius2; }
    bool full() const { return true; }
};

/// For every point of @a from, whether a point of @a to matches it at each threshold (the share
/// matched, per threshold); and with @a consistency, each strand of @a from's consistency at each
/// threshold. Strands of @a from are independent: processed in parallel, summed in order.
void matchShare(const OrientedPoints& from, const OrientedPoints& to, const std::vector<OrientedThreshold>& thresholds, bool bidirectional,
                bool threaded, std::vector<double>& share, std::vector<double>* consistency)
{
    const std::size_t T = thresholds.size(), N = from.position.size();
    if (T > 32) throw ValueError("oriented match: " + std::to_string(T) + " thresholds: at most 32");
    double maxDistance = 0.0;
    for (const OrientedThreshold& t : thresholds) maxDistance = std::max(maxDistance, t.distance);
    std::vector<double> cosines(T);
    for (std::size_t t = 0; t < T; ++t) cosines[t] = std::cos(thresholds[t].angleDegrees * M_PI / 180.0);
    const PointCloud cloud{&to.position};
    const PointKdTree tree(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(16));
    // The points of each strand of @a from (consecutive): [first[s], first[s + 1]).
    std::vector<std::size_t> first{0};
    for (std::size_t i = 1; i <= N; ++i) if (i == N || from.strand[i] != from.strand[i - 1]) first.push_back(i);
    const std::size_t S = first.size() - 1;
    std::vector<std::uint32_t> matched(N, 0);                   // per point: a bit per threshold
    std::vector<double> strandConsistency(consistency ? S * T : 0);
    const std::uint32_t all = T == 32 ? ~0u : (1u << T) - 1u;
    auto run = [&](const tbb::blocked_range<std::size_t>& r) {
        std::vector<std::uint64_t> hits, strandHits;
        for (std::size_t s = r.begin(); s != r.end(); ++s) {
            strandHits.clear();
            for (std::size_t i = first[s]; i < first[s + 1]; ++i) {
                MatchVisitor v{to, thresholds, cosines, bidirectional, maxDistance * maxDistance, from.direction[i]};
                v.all = all;
                hits.clear();
                if (consistency) v.hits = &hits;
                const Vec3d q = from.position[i];
                tree.findNeighbors(v, q.asPointer(), nanoflann::SearchParams(32, 0.f, false));
                matched[i] = v.matched;
                if (!consistency) continue;
                // A point counts each strand it matches once.
                std::sort(hits.begin(), hits.end());
                hits.erase(std::unique(hits.begin(), hits.end()), hits.end());
                strandHits.insert(strandHits.end(), hits.begin(), hits.end());
            }
            if (!consistency) continue;
            // Per threshold, the most of this strand's points that match one and the same strand.
            std::sort(strandHits.begin(), strandHits.end());
            const double points = double(first[s + 1] - first[s]);
            for (std::size_t a = 0; a < strandHits.size();) {
                std::size_t b = a;
                while (b < strandHits.size() && strandHits[b] == strandHits[a]) ++b;
                double& best = strandConsistency[s * T + (strandHits[a] >> 32)];
                best = std::max(best, double(b - a) / points);
                a = b;
            }
        }
    };
    if (threaded) tbb::parallel_for(tbb::blocked_range<std::size_t>(0, S, 16), run);
    else run(tbb::blocked_range<std::size_t>(0, S));
    share.assign(T, 0.0);
    for (std::size_t t = 0; t < T; ++t) {
        std::size_t count = 0;
        for (std::size_t i = 0; i < N; ++i) count += (matched[i] >> t) & 1u;
        share[t] = N ? double(count) / double(N) : 0.0;
    }
    if (!consistency) return;
    consistency->assign(T, 0.0);
    for (std::size_t t = 0; t < T; ++t) {
        double sum = 0.0;
        for (std::size_t s = 0; s < S; ++s) sum += strandConsistency[s * T + t];  // in strand order
        (*consistency)[t] = S ? sum / double(S) : 0.0;
    }
}

} // namespace

std::vector<OrientedThreshold> hairGsThresholds()
{
    return {{0.002, 20.0}, {0.003, 30.0}, {0.004, 40.0}, {0.004, 90.0}};
}

std::vector<OrientedMatch> matchOrientedPoints(const StrandSet& predicted, const StrandSet& reference,
                                               const std::vector<OrientedThreshold>& thresholds, bool bidirectional, bool threaded)
{
    for (const OrientedThreshold& t : thresholds) {
        if (!(t.distance >= 0.0) || !std::isfinite(t.distance)) throw ValueError("oriented match: distance " + std::to_string(t.distance) + ": must be finite and >= 0");
        if (!(t.angleDegrees >= 0.0 && t.angleDegrees <= 180.0)) throw ValueError("oriented match: angle " + std::to_string(t.angleDegrees) + ": must be in [0, 180] degrees");
    }
    const OrientedPoints p = orientedPoints(predicted), r = orientedPoints(reference);
    if (p.position.empty()) throw ValueError("oriented match: the predicted hair has no segment");
    if (r.position.empty()) throw ValueError("oriented match: the reference hair has no segment");
    std::vector<double> precision, recall, consistency;
    matchShare(p, r, thresholds, bidirectional, threaded, precision, nullptr);
    matchShare(r, p, thresholds, bidirectional, threaded, recall, &consistency);
    std::vector<OrientedMatch> out(thresholds.size());
    for (std::size_t t = 0; t < thresholds.size(); ++t) {
        OrientedMatch& m = out[t];
        m.threshold = thresholds[t];
        m.precision = precision[t];
        m.recall = recall[t];
        m.f1 = m.precision + m.recall > 0.0 ? 2.0 * m.precision * m.recall / (m.precision + m.recall) : 0.0;
        m.strandConsistency = consistency[t];
    }
    return out;
}

namespace {

/// For every vertex of @a from, the distance to the nearest vertex of @a to.
std::vector<double> nearestDistances(const StrandSet& from, const StrandSet& to, bool threaded)
{
    std::vector<Vec3d> pts(to.positions.size());
    for (std::size_t i = 0; i < pts.size(); ++i) pts[i] = Vec3d(to.positions[i].x(), to.positions[i].y(), to.positions[i].z());
    const PointCloud cloud{&pts};
    const PointKdTree tree(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(16));
    std::vector<double> out(from.positions.size());
    auto run = [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
            const Vec3f& p = from.positions[i];
            const double q[3] = {p.x(), p.y(), p.z()};
            std::uint32_t index = 0;
            double d2 = 0.0;
            tree.knnSearch(q, 1, &index, &d2);
            out[i] = std::sqrt(d2);
        }
    };
    if (threaded) tbb::parallel_for(tbb::blocked_range<std::size_t>(0, out.size(), 1024), run);
    else run(tbb::blocked_range<std::size_t>(0, out.size()));
    return out;
}

} // namespace

ChamferDistances chamferDistances(const StrandSet& a, const StrandSet& b, bool threaded)
{
    if (a.positions.empty() || b.positions.empty()) throw ValueError("Chamfer distance: a hairstyle has no vertex");
    const std::vector<double> ab = nearestDistances(a, b, threaded), ba = nearestDistances(b, a, threaded);
    ChamferDistances c;
    for (double d : ab) c.aToB += d;  // in vertex order: independent of threads
    for (double d : ba) c.bToA += d;
    c.aToB /= double(ab.size());
    c.bToA /= double(ba.size());
    c.mean = 0.5 * (c.aToB + c.bToA);
    c.perStrandA.assign(a.numStrands(), 0.0);
    for (std::size_t s = 0; s < a.numStrands(); ++s) {
        double sum = 0.0;
        for (std::size_t k = a.begin(s); k < a.begin(s) + a.size(s); ++k) sum += ab[k];
        c.perStrandA[s] = a.size(s) ? sum / double(a.size(s)) : 0.0;
    }
    return c;
}

StrandPairErrors strandPairErrors(const StrandSet& a, const StrandSet& b, std::size_t samples, bool threaded)
{
    if (a.numStrands() != b.numStrands()) {
        throw ValueError("strand pairs: " + std::to_string(a.numStrands()) + " strands against " + std::to_string(b.numStrands()) + ": the counts must agree");
    }
    if (samples < 3) throw ValueError("strand pairs: " + std::to_string(samples) + " samples: at least 3 (a curvature needs three points)");
    const std::size_t S = a.numStrands();
    StrandPairErrors e;
    e.position.assign(S, 0.0);
    e.curvature.assign(S, 0.0);
    // The curvature of the circle through three points: 2 sin(angle at q) / |r - p|.
    auto curvature = [](const Vec3f& p, const Vec3f& q, const Vec3f& r) {
        const Vec3d u(q.x() - p.x(), q.y() - p.y(), q.z() - p.z()), v(r.x() - q.x(), r.y() - q.y(), r.z() - q.z());
        const Vec3d w = u + v;
        const double lu = u.length(), lv = v.length(), lw = w.length();
        if (!(lu > 0.0) || !(lv > 0.0) || !(lw > 0.0)) return 0.0;
        return 2.0 * u.cross(v).length() / (lu * lv * lw);
    };
    auto run = [&](const tbb::blocked_range<std::size_t>& range) {
        std::vector<Vec3f> ra(samples), rb(samples);
        for (std::size_t i = range.begin(); i != range.end(); ++i) {
            if (a.size(i) == 0 || b.size(i) == 0) continue;
            resamplePolyline(a.positions.data() + a.begin(i), a.size(i), samples, ra.data());
            resamplePolyline(b.positions.data() + b.begin(i), b.size(i), samples, rb.data());
            const Vec3f shift = ra[0] - rb[0];
            double position = 0.0, curv = 0.0;
            for (std::size_t k = 0; k < samples; ++k) position += double((ra[k] - (rb[k] + shift)).length());
            for (std::size_t k = 1; k + 1 < samples; ++k) {
                curv += std::abs(curvature(ra[k - 1], ra[k], ra[k + 1]) - curvature(rb[k - 1], rb[k], rb[k + 1]));
            }
            e.position[i] = position / double(samples);
            e.curvature[i] = curv / double(samples - 2);
        }
    };
    if (threaded) tbb::parallel_for(tbb::blocked_range<std::size_t>(0, S, 64), run);
    else run(tbb::blocked_range<std::size_t>(0, S));
    for (std::size_t i = 0; i < S; ++i) {  // in strand order: independent of threads
        e.meanPosition += e.position[i];
        e.meanCurvature += e.curvature[i];
    }
    if (S) {
        e.meanPosition /= double(S);
        e.meanCurvature /= double(S);
    }
    return e;
}

namespace {

/// Calls @a visit with the packed voxel of every point of strand @a i (vertices, and points at
/// most half a voxel apart on each segment).
template <typename Visit>
void visitStrandVoxels(const StrandSet& s, std::size_t i, double voxel, Visit&& visit)
{
    const auto pack = [&](const Vec3d& p) {
        const auto c = [&](double v) { return std::uint64_t(std::int64_t(std::llround(v / voxel)) + (std::int64_t(1) << 20)) & 0x1fffff; };
        return c(p.x()) | (c(p.y()) << 21) | (c(p.z()) << 42);
    };
    const Vec3f* p = s.data(i);
    const std::size_t n = s.size(i);
    for (std::size_t k = 0; k < n; ++k) {
        const Vec3d a(p[k].x(), p[k].y(), p[k].z());
        if (!visit(pack(a))) return;
        if (k + 1 == n) break;
        const Vec3d b(p[k + 1].x(), p[k + 1].y(), p[k + 1].z());
        const double steps = std::ceil((b - a).length() / (0.5 * voxel));
        if (!(steps < double(1 << 24))) throw ValueError("voxel " + std::to_string(voxel) + ": a segment of strand " + std::to_string(i) + " would take over 2^24 points");
        const std::size_t m = std::size_t(steps);
        for (std::size_t j = 1; j < m; ++j) {
            if (!visit(pack(a + (b - a) * (double(j) / double(m))))) return;
        }
    }
}

} // namespace

std::size_t countStrandsLeavingVolume(const StrandSet& strands, const StrandSet& reference, double voxel, bool threaded)
{
    if (!(voxel > 0.0) || !std::isfinite(voxel)) throw ValueError("voxel " + std::to_string(voxel) + ": must be a positive length");
    for (const StrandSet* s : {&strands, &reference}) {
        const BBox box = computeBBox(*s);
        if (s->empty()) continue;
        const double reach = std::max({std::abs(double(box.min.x())), std::abs(double(box.min.y())), std::abs(double(box.min.z())),
                                       std::abs(double(box.max.x())), std::abs(double(box.max.y())), std::abs(double(box.max.z()))});
        if (!(reach / voxel < double(1 << 19))) {
            throw ValueError("voxel " + std::to_string(voxel) + ": over 2^19 voxels from the origin to the hair (" + std::to_string(reach) + "); give a larger voxel");
        }
    }
    std::unordered_set<std::uint64_t> occupied;
    for (std::size_t i = 0; i < reference.numStrands(); ++i) {
        visitStrandVoxels(reference, i, voxel, [&](std::uint64_t key) {
            occupied.insert(key);
            return true;
        });
    }
    // Dilated by one voxel: the 27 packed offsets (21 bits a coordinate; no coordinate reaches the wrap).
    std::unordered_set<std::uint64_t> volume;
    volume.reserve(occupied.size() * 4);
    for (const std::uint64_t key : occupied) {
        for (int dz = -1; dz <= 1; ++dz)
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) {
                    const std::uint64_t x = ((key & 0x1fffff) + std::uint64_t(dx)) & 0x1fffff;
                    const std::uint64_t y = (((key >> 21) & 0x1fffff) + std::uint64_t(dy)) & 0x1fffff;
                    const std::uint64_t z = (((key >> 42) & 0x1fffff) + std::uint64_t(dz)) & 0x1fffff;
                    volume.insert(x | (y << 21) | (z << 42));
                }
    }
    std::vector<char> leaves(strands.numStrands(), 0);
    auto body = [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
            visitStrandVoxels(strands, i, voxel, [&](std::uint64_t key) {
                if (volume.count(key)) return true;
                leaves[i] = 1;
                return false;
            });
        }
    };
    if (threaded) tbb::parallel_for(tbb::blocked_range<std::size_t>(0, strands.numStrands(), 256), body);
    else body(tbb::blocked_range<std::size_t>(0, strands.numStrands()));
    std::size_t count = 0;
    for (char c : leaves) count += std::size_t(c);
    return count;
}

} // namespace vdbhair
