#include "PiecewiseFit.h"

#include <vdbhair/helicoid/impl/SplitSearch.h>

namespace vdbhair {
namespace fit {

void fitPieces(PieceFitter& fitter, const PiecewiseOptions& options, StrandFit& f)
{
    const FitTarget& target = fitter.target();
    const FitParams& params = fitter.params();
    const std::size_t last = target.pts.size() - 1;
    f.pieces.clear();
    PieceStart start;
    start.p0 = f.root;
    start.q = f.frame;
    SplitOptions split;
    split.strategy = params.splitSearch;
    split.minLength = options.minLength;
    HelicoidTrace trace;
    while (start.a < last) {
        const std::size_t a = start.a;
        const double remaining = target.length - target.arc[a];
        split.lastPiece = int(f.pieces.size()) + 1 >= options.maxPieces || remaining < 2.0 * options.minLength || last - a < 3;
        FragmentCandidates candidates(fitter, start, options.tolerance);
        PieceChoice choice = choosePiece(candidates, split);
        split.previousTurn = choice.upperTurn;
        std::vector<double>& x = choice.x;
        const std::size_t b = choice.end;
        // Keep the piece and continue from its end, with its frame.
        const double L = target.arc[b] - target.arc[a];
        for (int shrink = 0; shrink < 30 && options.kept == KeptPieces::ClearOfAxis &&
                             fitter.tracePoints(x, L, start.p0, start.q, fitter.step(), fitter.scratchPoints()) < params.axisClearance;
             ++shrink) {
            for (int k = 0; k < 3; ++k) x[std::size_t(k)] *= 0.8;
        }
        const HelicoidPiece pc = scaledPiece(x, L);
        fitter.tracePiece(x, L, start.p0, start.q, fitter.step(), trace);  // chain pieces as they will be grown
        start.p0 = trace.points.back();
        start.q = trace.frames.back();
        start.previous = x;
        for (int k = 0; k < 3; ++k) start.previous[std::size_t(k)] = start.previous[std::size_t(k)] / L;  // unscaled for the next start
        f.pieces.push_back(pc);
        start.a = b;
    }
}

} // namespace fit
} // namespace vdbhair
