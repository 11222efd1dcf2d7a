// The options many verbs share, declared once: the readers' (readParameters()), the run's
// (runParameters(): threads) and compare's unit and thresholds (compareParameters()). Each front
// end makes its options from these tables; docs/cli.md shows them.
#include "TestUtil.h"

#include <vdbhair/RunOptions.h>
#include <vdbhair/compare/HairComparison.h>
#include <vdbhair/io/ReadOptions.h>
#include <vdbhair/io/StrandIO.h>

using namespace vdbhair;

namespace {

using vdbhair::test::cliPage;

template<typename P>
const Param<P>& declared(const ParamTable<P>& table, const std::string& name)
{
    const Param<P>* p = findParam(table, name);
    REQUIRE(p != nullptr);
    return *p;
}

template<typename P, typename T>
void setParam(const ParamTable<P>& table, const std::string& name, P& p, T value)
{
    std::get<ParamAccess<P, T>>(declared(table, name).access).set(p, value);
}

/// The message of what @a f throws, spelled in @a spelling.
template<typename F>
std::string thrown(F f, ParamSpelling spelling)
{
    try {
        f();
    } catch (const std::exception& e) {
        return spelledMessage(e, spelling);
    }
    return "nothing thrown";
}

} // namespace

TEST_CASE("Shared options: the readers' options set what the readers read, in docs/cli.md", "[params]")
{
    const ParamTable<ReadOptions>& t = readParameters();
    CHECK(declared(t, "strict").flag() == "--strict");
    CHECK(declared(t, "points-per-strand").pythonName() == "points_per_strand");
    CHECK(declared(t, "roots").defaultText() == "first");
    CHECK(declared(t, "grid").defaultText() == ReadOptions{}.vdbGrid);
    ReadOptions o;
    setParam(t, "strict", o, true);
    setParam(t, "roots", o, std::string("auto"));
    setParam(t, "curve-samples", o, std::uint64_t(9));
    setParam(t, "grid", o, std::string("strands_input"));
    CHECK(o.shortStrands == ShortStrandPolicy::Reject);
    CHECK(o.roots == RootEnd::Auto);
    CHECK(o.curveSamples == 9);
    CHECK(o.vdbGrid == "strands_input");
    // A curve of one sample: refused before any file is read, named as each front end spells it.
    o.curveSamples = 1;
    CHECK(thrown([&] { checkReadOptions(o); }, ParamSpelling::Keyword) == "curve_samples 1: must be 0 (automatic) or 2 or more");
    CHECK(thrown([&] { readStrands("missing.hair", o); }, ParamSpelling::Flag) == "--curve-samples 1: must be 0 (automatic) or 2 or more");
    REQUIRE_NOTHROW(checkReadOptions(ReadOptions{}));
    INFO("docs/cli.md's reading options table should read:\n" << parameterMarkdown(t));
    CHECK(cliPage().find(parameterMarkdown(t)) != std::string::npos);
}

TEST_CASE("Shared options: threads, one range for both front ends, in docs/cli.md", "[params]")
{
    const ParamTable<RunOptions>& t = runParameters();
    CHECK(declared(t, "threads").defaultText() == "0");
    CHECK(thrown([&] { checkParams(t, RunOptions{-1}, ParamSpelling::Flag, ""); }, ParamSpelling::Flag) == "--threads -1: must be at least 0");
    CHECK(thrown([&] { checkParams(t, RunOptions{-1}, ParamSpelling::Keyword, ""); }, ParamSpelling::Keyword) == "threads -1: must be at least 0");
    REQUIRE_NOTHROW(checkParams(t, RunOptions{4}, ParamSpelling::Flag, ""));
    INFO("docs/cli.md's common options table should read:\n" << parameterMarkdown(t));
    CHECK(cliPage().find(parameterMarkdown(t)) != std::string::npos);
}

TEST_CASE("Shared options: compare's unit and thresholds, one meaning and one error for both front ends", "[params]")
{
    const ParamTable<CompareParams>& t = compareParameters();
    CompareParams p;
    CHECK(declared(t, "unit").defaultText().empty());
    setParam(t, "unit", p, std::string("cm"));
    CHECK(p.metersPerUnit == 0.01);
    CHECK(declared(t, "unit").valueText(p) == "cm");
    setParam(t, "unit", p, std::string("0.3048"));
    CHECK(p.metersPerUnit == 0.3048);
    CHECK(declared(t, "unit").valueText(p) == "0.3048");
    const auto badUnit = [&] { setParam(t, "unit", p, std::string("furlong")); };
    CHECK(thrown(badUnit, ParamSpelling::Flag) == "--unit 'furlong': expected mm, cm, dm, m, in or the unit's length in metres (0.01 for centimetres)");
    CHECK(thrown(badUnit, ParamSpelling::Keyword) == "unit 'furlong': expected mm, cm, dm, m, in or the unit's length in metres (0.01 for centimetres)");
    // Thresholds as typed, several separated by spaces (the command line repeats its option).
    setParam(t, "threshold", p, std::string("2:20 3.5:30"));
    REQUIRE(p.thresholds.size() == 2);
    CHECK(p.thresholds[1].distance == 3.5);
    CHECK(p.thresholds[1].angleDegrees == 30.0);
    CHECK(declared(t, "threshold").valueText(p) == "2:20 3.5:30");
    const auto badThreshold = [&] { setParam(t, "threshold", p, std::string("2:20 2")); };
    CHECK(thrown(badThreshold, ParamSpelling::Flag) ==
          "--threshold '2': expected DISTANCE:ANGLE, a positive distance (millimetres with --unit, else file units) and an angle in [0, 180] degrees, e.g. 2:20");
    CHECK(thrown(badThreshold, ParamSpelling::Keyword) ==
          "threshold '2': expected DISTANCE:ANGLE, a positive distance (millimetres with unit, else file units) and an angle in [0, 180] degrees, e.g. 2:20");
}

TEST_CASE("Shared options: compare's thresholds are millimetres with a unit, HairGS's by default", "[compare]")
{
    // Two straight bundles 0.25 units apart in cm: 2.5 mm.
    StrandSet a, b;
    for (int s = 0; s < 6; ++s) {
        std::vector<Vec3f> pa, pb;
        for (int v = 0; v < 12; ++v) {
            pa.emplace_back(float(s), float(v) * 0.5f, 0.f);
            pb.emplace_back(float(s), float(v) * 0.5f, 0.25f);
        }
        a.addStrand(pa);
        b.addStrand(pb);
    }
    CompareParams p;
    p.metersPerUnit = 0.01;
    const HairComparison byDefault = compareHairstyles(a, b, p);
    REQUIRE(byDefault.oriented.size() == 4);
    CHECK(byDefault.oriented[0].f1 == 0.0);  // 2 mm: too close
    CHECK(byDefault.oriented[1].f1 == 1.0);  // 3 mm
    setParam(compareParameters(), "threshold", p, std::string("2:20 3:30"));
    const HairComparison given = compareHairstyles(a, b, p);
    REQUIRE(given.oriented.size() == 2);
    CHECK(given.oriented[0].threshold.distance == byDefault.oriented[0].threshold.distance);
    CHECK(given.oriented[1].f1 == 1.0);
    INFO("docs/cli.md's compare table should read:\n" << parameterMarkdown(compareParameters()));
    CHECK(cliPage().find(parameterMarkdown(compareParameters())) != std::string::npos);
}
