#include "SplitSearch.h"

#include <vdbhair/strands/Measures.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace vdbhair {
namespace fit {

bool FragmentCandidates::fit(std::size_t b, std::vector<double>& x, const CandidateOptions& options)
{
    const FitTarget& target = mFitter.target();
    int verdict = -1;  // the last pre-fit's acceptance, when known
    PieceFitOptions o;
    o.starts.which = options.which;
    o.starts.hint = options.hint;
    o.starts.hintLength = options.hint ? target.arc[options.hintEnd] - target.arc[mStart.a] : 0.0;
    o.startsToRun = options.startsToRun;
    o.prefitStop = kPrefitStopFraction * mTolerance;
    o.accept = [&](const std::vector<double>& y) {
        verdict = acceptable(b, y, mTolerance) ? 1 : 0;
        return verdict == 1;
    };
    x = mFitter.fitPiece(mStart, b, o);
    return verdict == 1 ? true : acceptable(b, x, mTolerance);
}

bool FragmentCandidates::polish(std::size_t b, std::vector<double>& x, bool ok)
{
    std::vector<double> y = x;
    mFitter.polish(y, mStart, b);
    const bool okAfter = acceptable(b, y, mTolerance);
    if (okAfter || !ok) { x = y; return okAfter; }
    return ok;
}

bool fitRemainder(FragmentCandidates& candidates, bool lastPiece, std::vector<double>& x)
{
    const std::size_t last = candidates.fitter().target().pts.size() - 1;
    const bool prefit = candidates.fitter().params().prefitIterations > 0;
    CandidateOptions o;
    o.startsToRun = lastPiece ? kLastPieceStarts : 0;
    bool ok = candidates.fit(last, x, o);
    if (prefit && (lastPiece || ok || candidates.acceptable(last, x, kPolishMargin * candidates.tolerance()))) ok = candidates.polish(last, x, ok);
    return ok;
}

std::size_t searchForward(FragmentCandidates& candidates, const SplitOptions& options, std::vector<double>& xu)
{
    // Candidates [a, b] with b in [lo, hiMax] (leaving at least the minimum fragment) or the whole
    // remainder. The first candidate ends where the strand has turned as much as the previous
    // piece's limit did (kSearchTurn for the first piece): gallop up from an acceptable candidate
    // by kSearchGrowth, down by halves from an unacceptable one, then bisect. Each candidate
    // starts from the nearest fit found.
    const FitTarget& target = candidates.fitter().target();
    const std::size_t a = candidates.start().a, last = target.pts.size() - 1;
    const double minLength = options.minLength, tolerance = candidates.tolerance();
    const std::size_t lo = std::min(last, std::max(a + 2, target.indexAtArc(target.arc[a] + minLength)));
    std::size_t hiMax = last;
    while (hiMax > a && (last - hiMax < 2 || target.arc[last] - target.arc[hiMax] < minLength)) --hiMax;
    auto snap = [&](std::size_t c) { return c > hiMax ? last : std::max(c, lo); };
    const double budget = options.previousTurn > 0.0 ? options.previousTurn : kSearchTurn;
    std::size_t g = a + 1;
    for (double turned = 0.0; g < last && turned + target.turning[g] <= budget; ++g) turned += target.turning[g];
    std::size_t good = a, bad = last + 1, c = snap(g);
    std::vector<double> xg, xb, xt;
    // The whole remainder, as the paper's first fit of a fragment: a pre-fit close to acceptable
    // is polished on Eq. 5 before it is judged.
    bool polishedLast = false;
    auto judgeLast = [&](std::size_t cand, std::vector<double>& y, bool ok) {
        if (ok || cand != last || !candidates.acceptable(last, y, kPolishMargin * tolerance)) return ok;
        polishedLast = true;
        return candidates.polish(last, y, false);
    };
    const bool okC = judgeLast(c, xt, candidates.fit(c, xt, {PieceStarts::All, nullptr, 0, c == last ? kLastPieceStarts : 0}));
    (okC ? good : bad) = c;
    (okC ? xg : xb) = xt;
    if (okC) {
        // Gallop up.
        while (good < last) {
            c = snap(a + std::size_t(std::ceil(double(good - a) * kSearchGrowth)));
            if (judgeLast(c, xt, candidates.fit(c, xt, {PieceStarts::NearestFit, &xg, good}))) { good = c; xg = xt; }
            else { bad = c; xb = xt; break; }
        }
    } else {
        // Halve down to the minimum fragment (which gets every start).
        while (bad > lo) {
            c = std::max(lo, a + (bad - a) / 2);
            if (candidates.fit(c, xt, {c == lo ? PieceStarts::All : PieceStarts::NearestFit, &xb, bad})) { good = c; xg = xt; break; }
            bad = c;
            xb = xt;
        }
    }
    std::size_t u;
    bool okU = false;
    if (good > a) {
        // Bisect between the longest acceptable and the shortest unacceptable candidate (below
        // the minimum remainder when the whole remainder failed).
        std::size_t top = bad == last ? hiMax + 1 : bad;
        const std::size_t resolution = std::size_t(std::max(1.0, kSplitResolution * double(last - a)));
        while (top > good + resolution) {
            const std::size_t mid = (good + top) / 2;
            const bool nearGood = mid - good <= top - mid || xb.empty();
            if (candidates.fit(mid, xt, {PieceStarts::NearestFit, nearGood ? &xg : &xb, nearGood ? good : bad})) { good = mid; xg = xt; }
            else { top = bad = mid; xb = xt; }
        }
        u = good;
        xu = xg;
        okU = true;
    } else {
        u = lo;
        xu = xb;
    }
    if (!(u == last && polishedLast)) candidates.polish(u, xu, okU);
    return u;
}

std::size_t searchTopDown(FragmentCandidates& candidates, const SplitOptions& options, const std::vector<double>& whole,
                          std::vector<double>& xu)
{
    // The longest prefix whose fit is acceptable (the paper's Fréchet threshold), by bisection
    // over the vertices between the minimum fragment and the remainder (which failed), starting at
    // kSplitFraction of the remainder. Each candidate starts from the nearest fit found so far.
    const FitTarget& target = candidates.fitter().target();
    const std::size_t a = candidates.start().a, last = target.pts.size() - 1;
    const double remaining = target.length - target.arc[a];
    const bool prefit = candidates.fitter().params().prefitIterations > 0;
    const std::size_t lo = std::min(last - 1, std::max(a + 2, target.indexAtArc(target.arc[a] + options.minLength)));
    const std::size_t hi = std::min(last - 1, std::max(lo, target.indexAtArc(target.arc[a] + kSplitFraction * remaining)));
    // Pre-fitted candidates start from their nearest fit alone; Nelder–Mead's from every start.
    const PieceStarts which = prefit ? PieceStarts::NearestFit : PieceStarts::All;
    std::vector<double> xt, xb = whole;
    std::size_t good = lo, bad = last, u = lo;
    bool okU = false;
    if (hi > lo && candidates.fit(hi, xt, {which, &xb, last})) {
        good = hi;
        xu = xt;
        okU = true;
    } else {
        if (hi > lo) { bad = hi; xb = xt; }
        okU = candidates.fit(lo, xu, {PieceStarts::All, hi > lo ? &xb : nullptr, bad});
    }
    if (okU) {
        const std::size_t resolution = std::size_t(std::max(1.0, kSplitResolution * double(last - a)));
        while (bad - good > resolution) {
            const std::size_t mid = (good + bad) / 2;
            const bool nearGood = mid - good <= bad - mid;
            if (candidates.fit(mid, xt, {which, nearGood ? &xu : &xb, nearGood ? good : bad})) { good = mid; xu = xt; }
            else { bad = mid; xb = xt; }
        }
        u = good;
    }
    if (prefit) candidates.polish(u, xu, okU);
    return u;
}

std::size_t backtrackSplit(FragmentCandidates& candidates, std::size_t u, const std::vector<double>& xu, double minLength)
{
    // Backtrack from u along the curvature profile to where fragment and fit agree best: in
    // curvature (the paper's criterion) and, since the next piece starts there, in position and
    // direction.
    const PieceFitter& fitter = candidates.fitter();
    const FitTarget& target = fitter.target();
    const PieceStart& s = candidates.start();
    const std::size_t a = s.a, last = target.pts.size() - 1;
    const double Lu = target.arc[u] - target.arc[a];
    HelicoidTrace trace;
    fitter.tracePiece(xu, Lu, s.p0, s.q, fitter.evalStep(), trace);
    std::vector<Vec3f> tf(trace.points.size());
    for (std::size_t i = 0; i < tf.size(); ++i) tf[i] = toFloat(trace.points[i]);
    std::vector<float> fitCurv(tf.size());
    curvatureProfile(tf.data(), tf.size(), fitCurv.data());
    std::size_t cut = u;
    double bestScore = std::numeric_limits<double>::max();
    // A fit that ends on the strand, in its direction, keeps its whole length: backtracking
    // exists for the fits that drift near their end.
    const double endOffset = (trace.points.back() - target.pts[u]).length();
    const double endAngle = std::acos(std::max(-1.0, std::min(1.0, trace.frames.back().t.dot((target.pts[u] - target.pts[u - 1]).unitSafe()))));
    const bool keepU = endOffset < kKeepOffset * candidates.tolerance() && endAngle < kKeepAngle;
    // The window: the end of the piece (backtracking adjusts the split; it must not throw away
    // the length the search found acceptable).
    const double windowStart = std::max(target.arc[a] + minLength, target.arc[u] - kBacktrackWindow * (target.arc[u] - target.arc[a]));
    for (std::size_t v = u; !keepU && v > a + 1 && target.arc[v] >= windowStart; --v) {
        const double sv = target.arc[v] - target.arc[a];
        const std::size_t m = std::min(tf.size() - 1, std::size_t(std::lround(sv / fitter.evalStep())));
        const Vec3d targetDir = (target.pts[std::min(v + 1, last)] - target.pts[v - 1]).unitSafe();
        const double angle = std::acos(std::max(-1.0, std::min(1.0, trace.frames[m].t.dot(targetDir))));
        const double score = std::abs(double(target.curvature[v]) - double(fitCurv[m])) * target.length + angle / 0.05;
        if (score < bestScore) { bestScore = score; cut = v; }
    }
    return cut;
}

PieceChoice choosePiece(FragmentCandidates& candidates, const SplitOptions& options)
{
    const FitTarget& target = candidates.fitter().target();
    const std::size_t a = candidates.start().a, last = target.pts.size() - 1;
    // The forward search compares pre-fits: without them the paper's search runs.
    const bool forward = options.strategy == SplitSearch::Forward && candidates.fitter().params().prefitIterations > 0;
    PieceChoice choice;
    choice.end = last;
    choice.upperTurn = options.previousTurn;
    std::size_t u = last;
    std::vector<double> xu;
    if (forward && !options.lastPiece) {
        u = searchForward(candidates, options, xu);
        if (u == last) {
            choice.x = xu;
            return choice;
        }
    } else {
        // The whole remainder first; the last piece allowed is kept whatever its error.
        // (With the forward search only the last piece allowed comes here.)
        if (fitRemainder(candidates, options.lastPiece, choice.x) || options.lastPiece) return choice;
        u = searchTopDown(candidates, options, choice.x, xu);
    }
    // Split at u, backtracked; the piece fitted to [a, u] is kept up to the split (its scaled
    // parameters rescaled from u's length to the cut's).
    choice.upperTurn = 0.0;
    for (std::size_t v = a + 1; v < u; ++v) choice.upperTurn += target.turning[v];
    choice.end = backtrackSplit(candidates, u, xu, options.minLength);
    const double Lu = target.arc[u] - target.arc[a], Lb = target.arc[choice.end] - target.arc[a];
    choice.x = xu;
    for (int k = 0; k < 3; ++k) choice.x[std::size_t(k)] *= Lb / Lu;
    return choice;
}

} // namespace fit
} // namespace vdbhair
