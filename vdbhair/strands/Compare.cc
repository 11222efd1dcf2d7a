#include "Compare.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/Memory.h>
#include <vdbhair/Parallel.h>
#include <vdbhair/strands/Resample.h>

#include <nlohmann/json.hpp>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <limits>
#include <cmath>
#include <string>

namespace vdbhair {

StrandIndex::StrandIndex(const StrandSet& strands, bool threaded) : mStrands(&strands), mGrid(strands.positions, threaded)
{
    const std::size_t V = strands.numVertices(), S = strands.numStrands();
    reserveHugePages(mDirection, V);  // a fresh page costs a fault (Memory.h)
    reserveHugePages(mStrandOf, V);
    mDirection.assign(V, Vec3f(0.f));
    mStrandOf.resize(V);
    forEachIndex(S, threaded, [&](std::size_t s) {
        const Vec3f* p = strands.data(s);
        for (std::size_t k = 0; k < strands.size(s); ++k) {
            mStrandOf[strands.begin(s) + k] = std::uint32_t(s);
            if (k + 1 == strands.size(s)) break;
            const Vec3d d(double(p[k + 1].x()) - p[k].x(), double(p[k + 1].y()) - p[k].y(), double(p[k + 1].z()) - p[k].z());
            const double l = d.length();
            if (l > 0.0) mDirection[strands.begin(s) + k] = Vec3f(float(d.x() / l), float(d.y() / l), float(d.z() / l));
        }
    }, 256);
    for (const Vec3f& d : mDirection) mOrientedPoints += d != Vec3f(0.f) ? 1 : 0;
    // Strands by the Morton code of their middle vertex, 10 bits an axis over the bounding box.
    {
        const Vec3d lo = mGrid.origin(), extent = mGrid.extent();
        const double longest = std::max({extent.x(), extent.y(), extent.z(), 1e-300});
        auto spread = [](std::uint64_t x) {  // 10 bits to every third of 30
            x &= 0x3ff;
            x = (x | x << 16) & 0x30000ff;
            x = (x | x << 8) & 0x300f00f;
            x = (x | x << 4) & 0x30c30c3;
            x = (x | x << 2) & 0x9249249;
            return x;
        };
        std::vector<std::uint64_t> key(S);
        for (std::size_t s = 0; s < S; ++s) {
            std::uint64_t m = 0;
            if (strands.size(s)) {
                const Vec3f& x = strands.positions[strands.begin(s) + strands.size(s) / 2];
                const Vec3d q = (Vec3d(x.x(), x.y(), x.z()) - lo) / longest * 1023.0;
                m = spread(std::uint64_t(q.x())) | spread(std::uint64_t(q.y())) << 1 | spread(std::uint64_t(q.z())) << 2;
            }
            key[s] = m << 32 | s;
        }
        std::sort(key.begin(), key.end());
        mOrder.resize(S);
        for (std::size_t s = 0; s < S; ++s) mOrder[s] = std::uint32_t(key[s]);
    }
    // Runs of up to kRun vertices of a strand, each in the sphere around its box's centre.
    mFirstRun.reserve(S + 1);
    for (std::size_t s = 0; s < S; ++s) {
        mFirstRun.push_back(mRunBegin.size());
        for (std::size_t b = strands.begin(s); b < strands.end(s); b += kRun) mRunBegin.push_back(b);
    }
    mFirstRun.push_back(mRunBegin.size());
    const std::size_t R = mRunBegin.size();
    mRunBegin.push_back(V);
    mRunCentre.resize(R);
    mRunRadius.resize(R);
    forEachIndex(S, threaded, [&](std::size_t s) {
        for (std::size_t r = mFirstRun[s]; r < mFirstRun[s + 1]; ++r) {
            const std::size_t b = mRunBegin[r], e = std::min(b + kRun, strands.end(s));
            BBox box;
            for (std::size_t v = b; v < e; ++v) box.expand(strands.positions[v]);
            const Vec3d c = 0.5 * (Vec3d(box.min.x(), box.min.y(), box.min.z()) + Vec3d(box.max.x(), box.max.y(), box.max.z()));
            double r2 = 0.0;
            for (std::size_t v = b; v < e; ++v) {
                const Vec3f& q = strands.positions[v];
                r2 = std::max(r2, (Vec3d(q.x(), q.y(), q.z()) - c).lengthSqr());
            }
            mRunCentre[r] = c;
            mRunRadius[r] = std::sqrt(r2);
        }
    }, 256);
}

namespace {

/// The thresholds as the tests use them: squared distances, cosines, the largest distance.
struct Thresholds
{
    std::vector<double> distance2, cosine;
    double maxDistance = 0.0;
    bool bidirectional = false;
    std::uint32_t all = 0;  ///< a bit per threshold

    Thresholds(const std::vector<OrientedThreshold>& t, bool bidirectional_) : bidirectional(bidirectional_)
    {
        if (t.size() > 32) throw ValueError("oriented match: " + std::to_string(t.size()) + " thresholds: at most 32");
        for (const OrientedThreshold& x : t) {
            distance2.push_back(x.distance * x.distance);
            cosine.push_back(std::cos(x.angleDegrees * M_PI / 180.0));
            maxDistance = std::max(maxDistance, x.distance);
        }
        all = t.size() == 32 ? ~0u : (1u << t.size()) - 1u;
    }

    /// The thresholds at which two oriented points at squared distance @a d2 match (a bit each).
    std::uint32_t bits(double d2, const Vec3d& u, const Vec3f& v) const
    {
        double c = u.x() * v.x() + u.y() * v.y() + u.z() * v.z();
        if (bidirectional) c = std::abs(c);
        std::uint32_t b = 0;
        for (std::size_t t = 0; t < cosine.size(); ++t) {
            if (d2 <= distance2[t] && c >= cosine[t]) b |= 1u << t;
        }
        return b;
    }
};

/// The thresholds at which an oriented point of strand @a q of @a to matches (@a p, @a u), of those
/// in @a want; stops when all of them match. @a hint: a vertex of @a to where the last match was
/// (updated; any other value for none). The vertices just after it are tried first (walking along
/// two strands side by side, the next match is there), then q's runs, the hint's first.
std::uint32_t matchStrand(const StrandIndex& to, const Thresholds& th, const Vec3d& p, const Vec3d& u, std::size_t q, std::size_t& hint,
                          std::uint32_t want)
{
    const std::size_t r0 = to.firstRun(q), r1 = to.firstRun(q + 1);
    if (r0 == r1) return 0;
    const std::size_t v0 = to.runBegin(r0), v1 = to.runBegin(r1);
    const std::vector<Vec3f>& x = to.strands().positions;
    const double maxD2 = th.maxDistance * th.maxDistance;
    std::uint32_t bits = 0;
    auto test = [&](std::size_t v) {
        if (!to.oriented(v)) return false;
        const double d2 = (p - Vec3d(x[v])).lengthSqr();
        if (d2 > maxD2) return false;
        const std::uint32_t b = th.bits(d2, u, to.direction(v)) & want;
        if (!(b & ~bits)) return false;
        bits |= b;
        hint = v;
        return bits == want;
    };
    const bool near = hint >= v0 && hint < v1;
    if (near) {
        const std::size_t h = hint;
        for (const std::size_t v : {h + 1, h, h + 2}) {
            if (v < v1 && test(v)) return bits;
        }
    }
    const std::size_t first = near ? r0 + (hint - v0) / StrandIndex::kRun : r0;
    for (std::size_t k = 0; k < r1 - r0; ++k) {
        const std::size_t r = k == 0 ? first : (r0 + k - 1 < first ? r0 + k - 1 : r0 + k);
        const double reach = to.runRadius(r) + th.maxDistance;
        if ((p - to.runCentre(r)).lengthSqr() > reach * reach) continue;
        for (std::size_t v = to.runBegin(r); v < to.runBegin(r + 1); ++v) {
            if (test(v)) return bits;
        }
    }
    return bits;
}

/// The thresholds at which any oriented point of @a to matches vertex @a v of @a from: the
/// strand that matched the point before first (a strand's neighbours run beside it), then the
/// grid out to the largest distance of the thresholds still unmatched, until every threshold
/// matches. @a lastStrand and @a hint carry the last match from point to point.
std::uint32_t matchAnyPoint(const StrandIndex& from, const StrandIndex& to, const Thresholds& th, std::size_t v,
                            std::uint32_t& lastStrand, std::size_t& hint)
{
    const std::size_t T = th.distance2.size();
    const Vec3d p = Vec3d(from.strands().positions[v]), u = Vec3d(from.direction(v));
    std::uint32_t bits = lastStrand != ~0u ? matchStrand(to, th, p, u, lastStrand, hint, th.all) : 0u;
    if (bits == th.all) return bits;
    double radius2 = 0.0;
    for (std::size_t t = 0; t < T; ++t) {
        if (!((bits >> t) & 1u)) radius2 = std::max(radius2, th.distance2[t]);
    }
    to.grid().forEachWithin(p, std::sqrt(radius2), [&](std::uint32_t w, double d2) {
        if (!to.oriented(w)) return true;
        const std::uint32_t b = th.bits(d2, u, to.direction(w));
        if (b & ~bits) {
            bits |= b;
            lastStrand = to.strandOf(w);
            hint = w;
        }
        return bits != th.all;
    });
    return bits;
}

/// One strand's consistency at each threshold, exactly (matchShare() explains the bound): the
/// most of its oriented points that match one and the same strand of @a to. Holds the scratch of
/// one thread, reused from strand to strand.
class ConsistencyCounter
{
public:
    /// @param matched per vertex of @a from, the thresholds at which it matches at all
    ConsistencyCounter(const StrandIndex& from, const StrandIndex& to, const Thresholds& th, const std::vector<std::uint32_t>& matched)
        : mFrom(from), mTo(to), mTh(th), mMatched(matched), mXf(from.strands().positions), T(th.distance2.size()),
          best(T), count(T), partial(T), listedAt(T), matchedAt(T), left(T)
    {
    }

    /// Each threshold's best count of the strand whose oriented points are @a points (not empty).
    const std::vector<std::size_t>& bestCounts(const std::vector<std::size_t>& points)
    {
        mPoints = &points;
        n = points.size();
        // M_t points match at t, and no strand can count more.
        std::fill(matchedAt.begin(), matchedAt.end(), 0);
        for (const std::size_t v : points) {
            for (std::size_t t = 0; t < T; ++t) matchedAt[t] += (mMatched[v] >> t) & 1u;
        }
        countLikelyStrands();
        const std::uint32_t complete = listMatches();
        countListedStrands(complete);
        return best;
    }

private:
    /// Strand q's matches of this strand's points at the thresholds of @a want, counted over the
    /// points that match at all, exactly as long as q can still beat the best count (a threshold
    /// is dropped once it cannot); the counts raise the best.
    void countStrand(std::uint32_t q, std::uint32_t want)
    {
        const std::vector<std::size_t>& points = *mPoints;
        std::fill(count.begin(), count.end(), 0);
        left = matchedAt;
        std::size_t h = ~std::size_t(0);
        for (std::size_t k = 0; k < n && want; ++k) {
            const std::size_t v = points[k];
            const std::uint32_t here = mMatched[v] & want;
            if (!here) continue;
            const std::uint32_t b = matchStrand(mTo, mTh, Vec3d(mXf[v]), Vec3d(mFrom.direction(v)), q, h, here);
            for (std::uint32_t t = 0, m = here; m; ++t, m >>= 1) {
                if (!(m & 1u)) continue;
                count[t] += (b >> t) & 1u;
                --left[t];
                if (count[t] + left[t] <= best[t]) want &= ~(1u << t);
            }
        }
        for (std::size_t t = 0; t < T; ++t) best[t] = std::max(best[t], count[t]);
    }

    /// L_t: the strands nearest the middle, the root and the tip, counted exactly.
    void countLikelyStrands()
    {
        const std::vector<std::size_t>& points = *mPoints;
        const auto settled = [&](std::size_t t) { return best[t] == matchedAt[t]; };
        std::fill(best.begin(), best.end(), 0);
        likely.clear();
        for (const std::size_t k : {n / 2, std::size_t(0), n - 1}) {
            std::uint32_t want = 0;
            for (std::size_t t = 0; t < T; ++t) want |= settled(t) ? 0u : 1u << t;
            if (!want) break;
            double d2 = std::numeric_limits<double>::infinity();
            const std::uint32_t w = mTo.grid().nearest(Vec3d(mXf[points[k]]), d2);
            if (w == ~0u) break;
            const std::uint32_t q = mTo.strandOf(w);
            if (std::find(likely.begin(), likely.end(), q) != likely.end()) continue;
            likely.push_back(q);
            countStrand(q, want);
        }
    }

    /// A strand that counts more than L_t at t matches one of any M_t - L_t of the points that
    /// match at t: every match of the first M_t - L_t of them finds all such strands, listed as
    /// strandHits. When that is half of them or more, listing all of them is cheaper than
    /// counting the strands found, and their counts come from the listing itself: those
    /// thresholds are the bits returned.
    std::uint32_t listMatches()
    {
        const std::vector<std::size_t>& points = *mPoints;
        std::size_t listing = 0;
        std::uint32_t complete = 0;
        for (std::size_t t = 0; t < T; ++t) {
            listedAt[t] = matchedAt[t] - best[t];
            if (listedAt[t] > 0 && 2 * listedAt[t] >= matchedAt[t]) {
                listedAt[t] = matchedAt[t];
                complete |= 1u << t;
            }
            listing += listedAt[t];
        }
        strandHits.clear();
        std::fill(partial.begin(), partial.end(), 0);  // here: the points listed so far at each t
        for (std::size_t k = 0; k < n && listing; ++k) {
            const std::size_t v = points[k];
            std::uint32_t active = 0;  // the thresholds still listing at this point
            double radius2 = 0.0;
            for (std::size_t t = 0; t < T; ++t) {
                if (!((mMatched[v] >> t) & 1u) || partial[t] == listedAt[t]) continue;
                active |= 1u << t;
                radius2 = std::max(radius2, mTh.distance2[t]);
                ++partial[t];
                --listing;
            }
            if (!active) continue;
            const Vec3d u = Vec3d(mFrom.direction(v));
            pointHits.clear();
            mTo.grid().forEachWithin(Vec3d(mXf[v]), std::sqrt(radius2), [&](std::uint32_t w, double d2) {
                if (!mTo.oriented(w)) return true;
                const std::uint32_t b = mTh.bits(d2, u, mTo.direction(w)) & active;
                for (std::uint32_t t = 0, m = b; m; ++t, m >>= 1) {
                    if (m & 1u) pointHits.push_back(std::uint64_t(mTo.strandOf(w)) << 32 | t);
                }
                return true;
            });
            // A point counts each strand it matches once.
            std::sort(pointHits.begin(), pointHits.end());
            pointHits.erase(std::unique(pointHits.begin(), pointHits.end()), pointHits.end());
            strandHits.insert(strandHits.end(), pointHits.begin(), pointHits.end());
        }
        return complete;
    }

    /// Per strand found: its matches among the listed points bound what it can count; those
    /// that can beat L are counted exactly.
    void countListedStrands(std::uint32_t complete)
    {
        std::sort(strandHits.begin(), strandHits.end());
        for (std::size_t a = 0; a < strandHits.size();) {
            const std::uint32_t q = std::uint32_t(strandHits[a] >> 32);
            std::fill(partial.begin(), partial.end(), 0);
            std::size_t b = a;
            for (; b < strandHits.size() && std::uint32_t(strandHits[b] >> 32) == q; ++b) ++partial[strandHits[b] & 0xffffffffu];
            a = b;
            std::uint32_t want = 0;
            for (std::size_t t = 0; t < T; ++t) {
                if ((complete >> t) & 1u) best[t] = std::max(best[t], partial[t]);  // the exact count
                else want |= partial[t] + (matchedAt[t] - listedAt[t]) > best[t] ? 1u << t : 0u;
            }
            if (want && std::find(likely.begin(), likely.end(), q) == likely.end()) countStrand(q, want);  // else counted already
        }
    }

    const StrandIndex& mFrom;
    const StrandIndex& mTo;
    const Thresholds& mTh;
    const std::vector<std::uint32_t>& mMatched;
    const std::vector<Vec3f>& mXf;
    const std::size_t T;
    const std::vector<std::size_t>* mPoints = nullptr;  ///< the strand's oriented points (vertex indices)
    std::size_t n = 0;                                   ///< their count
    std::vector<std::uint64_t> strandHits;  ///< strand << 32 | threshold, one per listed point that matches
    std::vector<std::uint64_t> pointHits;   ///< the same, for one point
    std::vector<std::uint32_t> likely;
    std::vector<std::size_t> best, count, partial, listedAt, matchedAt, left;
};

/// The mean over the strands of @a from with an oriented point of their consistency (S x T, in
/// strand order), per threshold.
void meanConsistency(const StrandIndex& from, const std::vector<double>& strandConsistency, std::size_t T, std::vector<double>& consistency)
{
    const StrandSet& fs = from.strands();
    const std::size_t S = fs.numStrands();
    std::size_t strands = 0;  // with an oriented point
    for (std::size_t s = 0; s < S; ++s) {
        for (std::size_t v = fs.begin(s); v < fs.end(s); ++v) {
            if (from.oriented(v)) {
                ++strands;
                break;
            }
        }
    }
    for (std::size_t t = 0; t < T; ++t) {
        double sum = 0.0;
        for (std::size_t s = 0; s < S; ++s) sum += strandConsistency[s * T + t];  // in strand order
        consistency[t] = strands ? sum / double(strands) : 0.0;
    }
}

/// For every oriented point of @a from, whether one of @a to matches it at each threshold (the
/// share matched, per threshold); and with @a consistency, each strand of @a from's consistency at
/// each threshold: the most of its points that match one and the same strand of @a to.
///
/// Consistency is found exactly without listing every match of every point. First each point's
/// thresholds (any match), M_t points matching at t: no strand counts more. A strand's best count
/// at t is at least L_t, the count of a likely strand (the one nearest its middle, root or tip),
/// counted exactly. A strand that counts more than L_t matches more than L_t of the M_t points, so
/// it matches one of any M_t - L_t of them: listing every match of the first M_t - L_t finds every
/// strand that can do better, and those are counted exactly. A close copy (L = M) lists nothing;
/// a poor match lists most points, as a plain count would.
/// Strands of @a from are independent: processed in parallel, summed in order.
void matchShare(const StrandIndex& from, const StrandIndex& to, const std::vector<OrientedThreshold>& thresholds, bool bidirectional,
                bool threaded, std::vector<double>& share, std::vector<double>* consistency)
{
    const Thresholds th(thresholds, bidirectional);
    const std::size_t T = thresholds.size();
    share.assign(T, 0.0);
    if (consistency) consistency->assign(T, 0.0);
    if (T == 0) return;
    const StrandSet& fs = from.strands();
    const std::size_t S = fs.numStrands();
    std::vector<std::uint32_t> matched;  // per oriented point: a bit per threshold
    reserveHugePages(matched, fs.numVertices());
    matched.assign(fs.numVertices(), 0);
    std::vector<double> strandConsistency(consistency ? S * T : 0);

    forEachRange(S, threaded, 16, [&](const tbb::blocked_range<std::size_t>& range) {
        std::vector<std::size_t> points;  // the strand's oriented points (vertex indices)
        ConsistencyCounter counter(from, to, th, matched);
        for (std::size_t o = range.begin(); o != range.end(); ++o) {
            const std::size_t s = from.spatialOrder()[o];
            points.clear();
            for (std::size_t v = fs.begin(s); v < fs.end(s); ++v) {
                if (from.oriented(v)) points.push_back(v);
            }
            if (points.empty()) continue;
            std::uint32_t lastStrand = ~0u;
            std::size_t hint = ~std::size_t(0);
            for (const std::size_t v : points) matched[v] = matchAnyPoint(from, to, th, v, lastStrand, hint);
            if (!consistency) continue;
            const std::vector<std::size_t>& best = counter.bestCounts(points);
            for (std::size_t t = 0; t < T; ++t) strandConsistency[s * T + t] = double(best[t]) / double(points.size());
        }
    });
    const std::size_t N = from.orientedPoints();
    for (std::size_t t = 0; t < T; ++t) {
        std::size_t c = 0;
        for (std::size_t v = 0; v < matched.size(); ++v) c += (matched[v] >> t) & 1u;
        share[t] = N ? double(c) / double(N) : 0.0;
    }
    if (consistency) meanConsistency(from, strandConsistency, T, *consistency);
}

} // namespace

std::vector<OrientedThreshold> hairGsThresholds()
{
    return {{0.002, 20.0}, {0.003, 30.0}, {0.004, 40.0}, {0.004, 90.0}};
}

std::vector<OrientedMatch> matchOrientedPoints(const StrandSet& predicted, const StrandSet& reference,
                                               const std::vector<OrientedThreshold>& thresholds, bool bidirectional, bool threaded)
{
    return matchOrientedPoints(StrandIndex(predicted, threaded), StrandIndex(reference, threaded), thresholds, bidirectional, threaded);
}

std::vector<OrientedMatch> matchOrientedPoints(const StrandIndex& predicted, const StrandIndex& reference,
                                               const std::vector<OrientedThreshold>& thresholds, bool bidirectional, bool threaded)
{
    for (const OrientedThreshold& t : thresholds) {
        if (!(t.distance >= 0.0) || !std::isfinite(t.distance)) throw ValueError("oriented match: distance " + std::to_string(t.distance) + ": must be finite and >= 0");
        if (!(t.angleDegrees >= 0.0 && t.angleDegrees <= 180.0)) throw ValueError("oriented match: angle " + std::to_string(t.angleDegrees) + ": must be in [0, 180] degrees");
    }
    if (predicted.orientedPoints() == 0) throw ValueError("oriented match: the predicted hair has no segment");
    if (reference.orientedPoints() == 0) throw ValueError("oriented match: the reference hair has no segment");
    std::vector<double> precision, recall, consistency;
    matchShare(predicted, reference, thresholds, bidirectional, threaded, precision, nullptr);
    matchShare(reference, predicted, thresholds, bidirectional, threaded, recall, &consistency);
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

/// Each search starts from the bound the previous vertex's nearest and its successor give (a
/// strand's neighbours run beside it); the distance found is exact whatever the bound.
std::vector<double> nearestVertexDistances(const StrandIndex& from, const StrandIndex& to, bool threaded)
{
    const StrandSet& fs = from.strands();
    const std::vector<Vec3f>& xt = to.strands().positions;
    std::vector<double> out;
    reserveHugePages(out, fs.numVertices());
    out.resize(fs.numVertices());
    forEachRange(fs.numStrands(), threaded, 16, [&](const tbb::blocked_range<std::size_t>& range) {
        for (std::size_t o = range.begin(); o != range.end(); ++o) {
            const std::size_t s = from.spatialOrder()[o];
            std::uint32_t last = ~0u;
            for (std::size_t v = fs.begin(s); v < fs.end(s); ++v) {
                const Vec3d p = Vec3d(fs.positions[v]);
                double d2 = std::numeric_limits<double>::infinity();
                if (last != ~0u) {
                    const std::uint32_t from = last;
                    for (std::uint32_t w = from; w < std::min<std::size_t>(std::size_t(from) + 2, xt.size()); ++w) {
                        const double e2 = (p - Vec3d(xt[w])).lengthSqr();
                        if (e2 < d2) {
                            d2 = e2;
                            last = w;
                        }
                    }
                }
                if (d2 > 0.0) last = to.grid().nearest(p, d2);  // else the bound's vertex: nothing is nearer
                out[v] = std::sqrt(d2);
            }
        }
    });
    return out;
}

ChamferDistances chamferDistances(const StrandSet& a, const StrandSet& b, bool threaded)
{
    if (a.positions.empty() || b.positions.empty()) throw ValueError("Chamfer distance: a hairstyle has no vertex");
    return chamferDistances(StrandIndex(a, threaded), StrandIndex(b, threaded), threaded);
}

ChamferDistances chamferDistances(const StrandIndex& ia, const StrandIndex& ib, bool threaded)
{
    const StrandSet &a = ia.strands(), &b = ib.strands();
    if (a.positions.empty() || b.positions.empty()) throw ValueError("Chamfer distance: a hairstyle has no vertex");
    const std::vector<double> ab = nearestVertexDistances(ia, ib, threaded), ba = nearestVertexDistances(ib, ia, threaded);
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

nlohmann::json toJson(const std::vector<OrientedMatch>& matches, double metersPerUnit)
{
    nlohmann::json oriented = nlohmann::json::array();
    for (const OrientedMatch& m : matches) {
        nlohmann::json t = {{"distance", m.threshold.distance}, {"angle_degrees", m.threshold.angleDegrees},
                            {"precision", m.precision}, {"recall", m.recall}, {"f1", m.f1},
                            {"strand_consistency", m.strandConsistency}};
        if (metersPerUnit > 0.0) t["distance_mm"] = m.threshold.distance * metersPerUnit * 1000.0;
        oriented.push_back(t);
    }
    return oriented;
}

} // namespace vdbhair
