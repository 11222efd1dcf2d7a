#include <vdbhair/io/ReadOptions.h>

namespace vdbhair {

const ParamTable<ReadOptions>& readParameters()
{
    using P = ReadOptions;
    static const ParamTable<P> table = [] {
        ParamTable<P> t;
        const ParamAccess<P, bool> strictAccess{[](const P& p) { return p.shortStrands == ShortStrandPolicy::Reject; },
                                                [](P& p, bool v) { p.shortStrands = v ? ShortStrandPolicy::Reject : ShortStrandPolicy::Drop; }};
        t.push_back(makeParam<P>("strict", "Reject strands of fewer than 2 vertices instead of dropping them", "", strictAccess));
        t.push_back(makeParam<P>("grid", "VDB input: the points grid holding the strands (e.g. strands_input)", "",
                                 member<P>([](P& p) -> std::string& { return p.vdbGrid; })));
        auto runs = makeParam<P>("points-per-strand",
                                 "For a .ply of points only (NeuralHaircut, GaussianHaircut: 100): each run of N consecutive points is one strand",
                                 "", member<P>([](P& p) -> std::size_t& { return p.pointsPerStrand; }));
        runs.zeroMeans = "not set: such a file is then an error that says to set it";
        t.push_back(runs);
        auto samples = makeParam<P>("curve-samples", "For .obj curves (curv) and cubic .usda/.abc curves: points per curve, evenly in its parameter",
                                    "", member<P>([](P& p) -> std::size_t& { return p.curveSamples; }));
        samples.zeroMeans = "automatic, within 1 % of the curve's length; 1 is refused";
        t.push_back(samples);
        auto roots = makeParam<P>("roots",
                                  "Which end of each stored strand is its root: first (the convention), last (every strand reversed), or auto, "
                                  "decided once for the file: the end nearer the verb's head in most strands when it has one, else the end whose "
                                  "sphere has more of the hair outside it (a warning says when it reversed them)",
                                  "", named<P>([](P& p) -> RootEnd& { return p.roots; }, rootEndName, rootEndFromName));
        roots.choices = {"first", "last", "auto"};
        roots.oldFlags = {"--root-end"};
        t.push_back(roots);
        return t;
    }();
    return table;
}

void checkReadOptions(const ReadOptions& opts)
{
    checkParams(readParameters(), opts, opts.spelling, "");
    if (opts.curveSamples == 1) {
        throw ParamError<ValueError>({readParamName("curve-samples"), " 1: must be 0 (automatic) or 2 or more"}, opts.spelling);
    }
}

} // namespace vdbhair
