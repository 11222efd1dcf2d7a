#include "TestUtil.h"

#include "../apps/AppParameters.h"

#include <vdbhair/Parameters.h>
#include <vdbhair/compare/HairComparison.h>
#include <vdbhair/dataset/Prepare.h>
#include <vdbhair/field/Refine.h>
#include <vdbhair/field/Streamline.h>
#include <vdbhair/field/TangentField.h>
#include <vdbhair/helicoid/GuideInterpolation.h>
#include <vdbhair/helicoid/HelicoidFit.h>
#include <vdbhair/helicoid/Reconstruction.h>
#include <vdbhair/helicoid/Scene.h>
#include <vdbhair/io/ConvertStrands.h>
#include <vdbhair/io/RootEnd.h>
#include <vdbhair/render/SliceRenderer.h>
#include <vdbhair/render/StrandRenderer.h>
#include <vdbhair/scalp/Follicles.h>
#include <vdbhair/scalp/ScalpInput.h>
#include <vdbhair/strands/StrandStats.h>
#include <vdbhair/synth/Comb.h>
#include <vdbhair/synth/HairTransfer.h>
#include <vdbhair/synth/Synthesis.h>

#include <algorithm>
#include <fstream>
#include <sstream>

using namespace vdbhair;
using Catch::Matchers::Contains;

namespace {

struct Toy
{
    int count = 3;
    double size = 0.5;
    bool on = false;
    std::string kind = "a";
};

ParamTable<Toy> toyTable()
{
    ParamTable<Toy> t;
    auto count = makeParam<Toy>("count", "How many", "", member<Toy>([](Toy& p) -> int& { return p.count; }));
    count.min = 1;
    count.max = 8;
    t.push_back(count);
    auto size = makeParam<Toy>("voxel-size", "How big", "world units", member<Toy>([](Toy& p) -> double& { return p.size; }));
    size.min = 0;
    size.zeroMeans = "pick one";
    t.push_back(size);
    t.push_back(makeParam<Toy>("on", "Whether", "", member<Toy>([](Toy& p) -> bool& { return p.on; })));
    auto kind = makeParam<Toy>("kind", "Which", "", member<Toy>([](Toy& p) -> std::string& { return p.kind; }));
    kind.choices = {"a", "b"};
    t.push_back(kind);
    return t;
}

using vdbhair::test::cliPage;

/// The option table of @a verb's own section of docs/cli.md (its `### verb` heading up to the next
/// heading): every row there, so that a row missing or extra fails, and another verb's table
/// (demo's is refine's but one) is never taken for it.
std::string cliTable(const std::string& verb)
{
    const std::string page = cliPage();
    const std::string heading = "\n### " + verb + "\n";
    const std::size_t start = page.find(heading);
    INFO("docs/cli.md has no section '### " << verb << "'");
    REQUIRE(start != std::string::npos);
    const std::size_t end = std::min(page.find("\n#", start + heading.size()), page.size());
    std::istringstream section(page.substr(start, end - start));
    std::string table, line;
    while (std::getline(section, line)) if (!line.empty() && line[0] == '|') table += line + "\n";
    return table;
}

} // namespace

TEST_CASE("Parameters: defaults come from the struct, ranges and choices are checked, names spelled per front end", "[params]")
{
    const ParamTable<Toy> t = toyTable();
    CHECK(t[0].defaultText() == "3");
    CHECK(t[1].defaultText() == "0.5");
    CHECK(t[2].defaultText() == "false");
    CHECK(t[3].defaultText() == "a");
    CHECK(t[1].pythonName() == "voxel_size");
    CHECK(paramHelp(t[1]) == "How big (world units; at least 0; 0: pick one)");
    CHECK(paramHelp(t[0]) == "How many (1 to 8)");
    Toy p;
    REQUIRE_NOTHROW(checkParams(t, p, ParamSpelling::Flag, ""));
    p.count = 9;
    REQUIRE_THROWS_WITH(checkParams(t, p, ParamSpelling::Flag, ""), "--count 9: must be between 1 and 8");
    REQUIRE_THROWS_WITH(checkParams(t, p, ParamSpelling::Keyword, "toy"), "toy: count 9: must be between 1 and 8");
    p = Toy{};
    p.size = -1;
    REQUIRE_THROWS_WITH(checkParams(t, p, ParamSpelling::Keyword, "toy"), "toy: voxel_size -1: must be at least 0 world units");
    p.size = std::numeric_limits<double>::quiet_NaN();
    REQUIRE_THROWS_WITH(checkParams(t, p, ParamSpelling::Flag, ""), Contains("--voxel-size nan: must be at least 0"));
    p = Toy{};
    p.kind = "c";
    REQUIRE_THROWS_WITH(checkParams(t, p, ParamSpelling::Flag, ""), "--kind 'c': must be one of a, b");
    // Setters write the struct's members.
    std::get<ParamAccess<Toy, int>>(t[0].access).set(p, 5);
    CHECK(p.count == 5);
    CHECK(parameterMarkdown(t) ==
          "| option | Python | default | what it does |\n| --- | --- | --- | --- |\n"
          "| `--count` | `count` | 3 | How many (1 to 8) |\n"
          "| `--voxel-size` | `voxel_size` | 0.5 | How big (world units; at least 0; 0: pick one) |\n"
          "| `--on` | `on` | false | Whether |\n"
          "| `--kind` | `kind` | a | Which (one of a, b) |\n");
}

TEST_CASE("Parameters: refine's declaration sets what the library reads, and docs/cli.md shows it", "[params]")
{
    const ParamTable<RefineParams>& t = refineParameters();
    RefineParams p;
    // step and integrator set both modes' (setStep()).
    std::get<ParamAccess<RefineParams, double>>(findParam(t, "step")->access).set(p, 0.25);
    std::get<ParamAccess<RefineParams, std::string>>(findParam(t, "integrator")->access).set(p, "rk4");
    CHECK(p.trace.step == 0.25);
    CHECK(p.consistency.step == 0.25);
    CHECK(p.trace.integrator == Integrator::RK4);
    CHECK(p.consistency.integrator == Integrator::RK4);
    std::get<ParamAccess<RefineParams, std::string>>(findParam(t, "mode")->access).set(p, "field");
    CHECK(p.mode == RefineMode::Field);
    // Every default passes its own range.
    REQUIRE_NOTHROW(checkParams(t, RefineParams{}, ParamSpelling::Flag, ""));
    // The page's table is the declaration's (regenerate it from parameterMarkdown() when this fails).
    INFO("docs/cli.md's refine table should read:\n" << parameterMarkdown(t));
    CHECK(cliTable("refine") == parameterMarkdown(t));
}

TEST_CASE("Parameters: field's declaration is refine's too (nested), and docs/cli.md shows it", "[params]")
{
    const ParamTable<FieldParams>& f = fieldParameters();
    // refine offers the field's voxel size, iterations and caps from the one declaration.
    for (const char* name : {"voxel-size", "iterations", "max-voxels", "max-memory"}) {
        const Param<RefineParams>* r = findParam(refineParameters(), name);
        REQUIRE(r);
        CHECK(paramHelp(*r) == paramHelp(*findParam(f, name)));
        CHECK(r->defaultText() == findParam(f, name)->defaultText());
    }
    RefineParams rp;
    std::get<ParamAccess<RefineParams, double>>(findParam(refineParameters(), "voxel-size")->access).set(rp, 0.75);
    CHECK(rp.field.voxelSize == 0.75);
    // field's table is the estimate's and the levels (fieldLevelsParameters()).
    const ParamTable<FieldLevelsParams>& fl = fieldLevelsParameters();
    for (const Param<FieldParams>& q : f) CHECK(paramHelp(*findParam(fl, q.name)) == paramHelp(q));
    CHECK(findParam(fl, "levels")->pythonNone);
    INFO("docs/cli.md's field table should read:\n" << parameterMarkdown(fl));
    CHECK(cliTable("field") == parameterMarkdown(fl));
}

TEST_CASE("Parameters: fit's declaration, a keyword that is not its name and a valued flag, in docs/cli.md", "[params]")
{
    const ParamTable<FitParams>& t = fitParameters();
    CHECK(findParam(t, "lambda")->pythonName() == "lambda_");
    CHECK(findParam(t, "roll")->valued);
    FitParams p;
    p.maxError = 0.0;
    REQUIRE_THROWS_WITH(checkParams(t, p, ParamSpelling::Flag, ""), "--max-error 0: must be above 0");
    REQUIRE_NOTHROW(checkParams(t, FitParams{}, ParamSpelling::Flag, ""));
    INFO("docs/cli.md's fit table should read:\n" << parameterMarkdown(t));
    CHECK(cliTable("fit") == parameterMarkdown(t));
}


TEST_CASE("Parameters: an axis by name, auto for the library's choice, any finite vector through its setter", "[params]")
{
    struct Axes
    {
        Vec3d up{0.0, 0.0, 0.0};
        Vec3d facing{0.0, 1.0, 0.0};
    };
    ParamTable<Axes> t;
    t.push_back(makeAxisParam<Axes>("up", "Up", [](Axes& a) -> Vec3d& { return a.up; }, "the roots' mean direction"));
    t.push_back(makeAxisParam<Axes>("facing", "Facing", [](Axes& a) -> Vec3d& { return a.facing; }));
    CHECK(t[0].isAxis());
    CHECK(t[0].defaultText() == "auto");
    CHECK(t[0].pythonNone);
    CHECK(t[1].defaultText() == "y");
    CHECK_FALSE(t[1].pythonNone);
    CHECK(paramHelp(t[0]) == "Up (one of auto, x, y, z, -x, -y, -z; auto: the roots' mean direction)");
    CHECK(paramHelp(t[1]) == "Facing (one of x, y, z, -x, -y, -z)");
    CHECK(axisFromText(t[0], "auto", "--up") == Vec3d(0.0));
    CHECK(axisFromText(t[1], "-z", "--facing") == Vec3d(0.0, 0.0, -1.0));
    REQUIRE_THROWS_WITH(axisFromText(t[1], "auto", "--facing"), "--facing 'auto': must be one of x, y, z, -x, -y, -z");
    Axes a;
    a.up = Vec3d(0.5, 0.5, 0.0);
    CHECK(t[0].valueText(a) == "(0.5, 0.5, 0)");
    REQUIRE_NOTHROW(checkParams(t, a, ParamSpelling::Flag, ""));
    a.facing = Vec3d(0.0);
    REQUIRE_THROWS_WITH(checkParams(t, a, ParamSpelling::Keyword, "toy"), "toy: facing (0, 0, 0): must be a non-zero vector");
    a.facing = Vec3d(std::numeric_limits<double>::infinity(), 0.0, 0.0);
    REQUIRE_THROWS_WITH(checkParams(t, a, ParamSpelling::Flag, ""), Contains("--facing (inf, 0, 0): must be a finite vector"));
}

namespace {

/// The declared parameter @a name of @a table, which must exist.
template<typename P>
const Param<P>& declared(const ParamTable<P>& table, const std::string& name)
{
    const Param<P>* p = findParam(table, name);
    INFO(name);
    REQUIRE(p);
    return *p;
}

template<typename P, typename T>
void setParam(const ParamTable<P>& table, const std::string& name, P& p, T value)
{
    std::get<ParamAccess<P, T>>(declared(table, name).access).set(p, value);
}

/// Every default passes its own range, and docs/cli.md holds the table.
template<typename P>
void checkDeclaration(const ParamTable<P>& t, const char* verb)
{
    REQUIRE_NOTHROW(checkParams(t, P{}, ParamSpelling::Flag, ""));
    for (const Param<P>& p : t) CHECK(paramHelp(p).find('|') == std::string::npos);  // a cell of a Markdown table
    INFO("docs/cli.md's " << verb << " table should read:\n" << parameterMarkdown(t));
    CHECK(cliTable(verb) == parameterMarkdown(t));
}

} // namespace

TEST_CASE("Parameters: retrace's declaration sets what the library reads, and docs/cli.md shows it", "[params]")
{
    const ParamTable<RetraceParams>& t = retraceParameters();
    // The trace's parameters (traceParameters(), nested) and the measure switch, in one table.
    for (const Param<TraceParams>& q : traceParameters()) CHECK(paramHelp(declared(t, q.name)) == paramHelp(q));
    CHECK(t.size() == traceParameters().size() + 1);
    RetraceParams p;
    setParam(t, "vertices", p, std::string("steps"));
    setParam(t, "max-steps", p, std::uint64_t(7));
    setParam(t, "measure", p, true);
    CHECK(p.trace.vertices == RetraceVertices::Steps);
    CHECK(p.trace.maxSteps == 7);
    CHECK(p.measure);
    CHECK(declared(t, "measure").flag() == "--measure");
    checkDeclaration(t, "retrace");
}

TEST_CASE("Parameters: interpolate's declaration, neighbours for both methods and the groom's ranges, in docs/cli.md", "[params]")
{
    const ParamTable<InterpolateParams>& t = interpolateParameters();
    InterpolateParams p;
    // neighbors: 0 (and Python's None) leaves each method's own; K sets both.
    CHECK(declared(t, "neighbors").defaultText() == "0");
    CHECK(declared(t, "neighbors").pythonNone);
    setParam(t, "neighbors", p, 7);
    CHECK(p.points.neighbors == 7);
    CHECK(p.helicoid.shepard.neighbors == 7);
    setParam(t, "neighbors", p, 0);
    CHECK(p.points.neighbors == PointInterpolationParams{}.neighbors);
    CHECK(p.helicoid.shepard.neighbors == ShepardParams{}.neighbors);
    setParam(t, "neighbors", p, -1);
    REQUIRE_THROWS_WITH(checkParams(t, p, ParamSpelling::Flag, ""), "--neighbors -1: must be at least 0");
    p = InterpolateParams{};
    // One cap for both methods; names set the enumerations.
    setParam(t, "max-vertices", p, std::uint64_t(1000));
    CHECK(p.points.maxVertices == 1000);
    CHECK(p.helicoid.maxVertices == 1000);
    setParam(t, "blend", p, std::string("arcs"));
    CHECK(p.helicoid.blend == HelicoidBlend::Arcs);
    setParam(t, "method", p, std::string("helicoid"));
    CHECK(p.method == InterpolationMethod::Helicoid);
    p = InterpolateParams{};
    p.groom.clump.tightness = 1.5;
    REQUIRE_THROWS_WITH(checkParams(t, p, ParamSpelling::Flag, ""), "--clump-tightness 1.5: must be between 0 and 1");
    p = InterpolateParams{};
    p.helicoid.shepard.power = 0.0;
    REQUIRE_THROWS_WITH(checkParams(t, p, ParamSpelling::Keyword, "interpolate"), "interpolate: power 0: must be above 0");
    checkDeclaration(t, "interpolate");
}

TEST_CASE("Parameters: reconstruct's declaration reuses interpolation's and fit's, in docs/cli.md", "[params]")
{
    const ParamTable<ReconstructParams>& t = reconstructParameters();
    // The same declarations as interpolate's and fit's; reconstruct's own default blend.
    for (const char* name : {"arcs", "power", "neighbors", "grouping", "likeness"}) {
        CHECK(paramHelp(declared(t, name)) == paramHelp(declared(interpolateParameters(), name)));
    }
    CHECK(paramHelp(declared(t, "max-error")) == paramHelp(declared(fitParameters(), "max-error")));
    CHECK(declared(t, "blend").defaultText() == "arcs");
    ReconstructParams p;
    setParam(t, "select", p, std::string("cluster"));
    CHECK(p.selection == GuideSelection::Cluster);
    setParam(t, "max-error", p, 0.05);
    CHECK(p.fit.maxError == 0.05);
    p = ReconstructParams{};
    p.guideFraction = 1.5;
    REQUIRE_THROWS_WITH(checkParams(t, p, ParamSpelling::Keyword, "reconstruct"), "reconstruct: guides 1.5: must be above 0 and at most 1");
    CHECK(guideSelectionFromName(guideSelectionName(GuideSelection::Random)) == GuideSelection::Random);
    REQUIRE_THROWS_WITH(guideSelectionFromName("best"), "select 'best' is not one of random, cluster");
    checkDeclaration(t, "reconstruct");
}

TEST_CASE("Parameters: roots's declaration, a flag that turns off what is on by default, in docs/cli.md", "[params]")
{
    const ParamTable<FollicleParams>& t = follicleParameters();
    CHECK(declared(t, "contour").flag() == "--no-contour");
    CHECK(declared(t, "contour").pythonName() == "contour");
    CHECK(declared(t, "count").flag() == "--count");
    CHECK(declared(t, "count").pythonNone);
    FollicleParams p;
    setParam(t, "contour", p, false);
    CHECK_FALSE(p.contour);
    setParam(t, "iterations", p, 12);
    CHECK(p.maxIterations == 12);
    p = FollicleParams{};
    p.initialFraction = 5.0;
    REQUIRE_THROWS_WITH(checkParams(t, p, ParamSpelling::Flag, ""), "--initial-fraction 5: must be above 0 and at most 4");
    checkDeclaration(t, "roots");
}

TEST_CASE("Parameters: grow's declaration, the scene's own integrator by name, in docs/cli.md", "[params]")
{
    const ParamTable<GrowOptions>& t = growParameters();
    CHECK(declared(t, "integrator").defaultText() == "scene");
    GrowOptions p;
    setParam(t, "integrator", p, std::string("rk4"));
    REQUIRE(p.integrator);
    CHECK(*p.integrator == HelicoidIntegrator::RK4);
    setParam(t, "integrator", p, std::string("scene"));
    CHECK_FALSE(p.integrator);
    checkDeclaration(t, "grow");
}

TEST_CASE("Parameters: synth's declaration is transfer's and comb's, each with its own struct's defaults, in docs/cli.md", "[params]")
{
    const ParamTable<SynthParams>& t = synthParameters();
    SynthParams p;
    std::get<ParamAccess<SynthParams, std::string>>(findParam(t, "root-density")->access).set(p, "even");
    std::get<ParamAccess<SynthParams, std::string>>(findParam(t, "layout")->access).set(p, "example");
    std::get<ParamAccess<SynthParams, std::string>>(findParam(t, "detail-scale")->access).set(p, "arc-length");
    std::get<ParamAccess<SynthParams, int>>(findParam(t, "levels")->access).set(p, 4);
    CHECK(!p.exampleDensity);
    CHECK(p.layout == SynthLayout::Example);
    CHECK(p.detailScale == DetailScale::ArcLength);
    CHECK(p.cluster.levels == 4);
    // transfer's defaults are TransferParams::synth's, comb's CombParams::synth's: never restated.
    const TransferParams transfer;
    CHECK(findParam(transferParameters(), "detail-scale")->defaultText() == detailScaleName(transfer.synth.detailScale));
    CHECK(findParam(transferParameters(), "match-candidates")->defaultText() == std::to_string(transfer.synth.match.candidates));
    CHECK(findParam(transferParameters(), "match-place")->defaultText() == formatNumber(transfer.synth.match.place));
    CHECK(findParam(t, "detail-scale")->defaultText() == detailScaleName(SynthParams{}.detailScale));
    CHECK(findParam(combParameters(), "levels")->defaultText() == std::to_string(CombParams{}.synth.cluster.levels));
    CHECK(findParam(t, "levels")->defaultText() == std::to_string(SynthParams{}.cluster.levels));
    // transfer keeps BASE's coarsest level: no layout of its own.
    CHECK(findParam(transferParameters(), "layout") == nullptr);
    CHECK(paramHelp(*findParam(transferParameters(), "threshold")) == paramHelp(*findParam(t, "threshold")));
    TransferParams tp;
    std::get<ParamAccess<TransferParams, int>>(findParam(transferParameters(), "match-candidates")->access).set(tp, 5);
    CHECK(tp.synth.match.candidates == 5);
    p = SynthParams{};
    p.cluster.levels = 9;
    REQUIRE_THROWS_WITH(checkParams(t, p, ParamSpelling::Keyword, "synth"), "synth: levels 9: must be between 2 and 5");
    REQUIRE_NOTHROW(checkParams(t, SynthParams{}, ParamSpelling::Flag, ""));
    REQUIRE_NOTHROW(checkParams(transferParameters(), TransferParams{}, ParamSpelling::Flag, ""));
    REQUIRE_NOTHROW(checkParams(combParameters(), CombParams{}, ParamSpelling::Flag, ""));
    INFO("docs/cli.md's synth, transfer and comb tables should read:\n" << parameterMarkdown(t) << "\n" << parameterMarkdown(transferParameters())
                                                                      << "\n" << parameterMarkdown(combParameters()));
    CHECK(cliTable("synth") == parameterMarkdown(t));
    CHECK(cliTable("transfer") == parameterMarkdown(transferParameters()));
    CHECK(cliTable("comb") == parameterMarkdown(combParameters()));
}

TEST_CASE("Parameters: scalp's declaration sets the level set's and the region's, a float as a number, in docs/cli.md", "[params]")
{
    const ParamTable<ScalpBuildParams>& t = scalpParameters();
    CHECK(declared(t, "half-width").defaultText() == formatNumber(ScalpParams{}.halfWidth));
    CHECK(declared(t, "region-threshold").defaultText() == formatNumber(kDefaultRegionThreshold));
    ScalpBuildParams p;
    setParam(t, "voxel-size", p, 0.25);
    setParam(t, "half-width", p, 2.0);
    setParam(t, "max-constraints", p, std::uint64_t(300));
    setParam(t, "region-radius", p, 3.0);
    setParam(t, "region-threshold", p, 0.25);
    CHECK(p.surface.maxConstraints == 300);
    CHECK(p.regionRadius == 3.0);
    CHECK(p.regionThreshold == 0.25);
    // What the level set is made with: its voxel and its band (half width x voxel size).
    const openvdb::FloatGrid::Ptr sphere = scalpFromSphere(Vec3d(0.0), 1.0, p.surface);
    CHECK(sphere->voxelSize().x() == Approx(0.25));
    CHECK(sphere->background() == Approx(0.5));
    p = ScalpBuildParams{};
    p.surface.halfWidth = 0.5f;
    REQUIRE_THROWS_WITH(checkParams(t, p, ParamSpelling::Flag, ""), "--half-width 0.5: must be between 1 and 64 voxels");
    p = ScalpBuildParams{};
    p.surface.maxConstraints = 4;
    REQUIRE_THROWS_WITH(checkParams(t, p, ParamSpelling::Keyword, "scalp"), "scalp: max_constraints 4: must be at least 5");
    p = ScalpBuildParams{};
    p.regionThreshold = std::numeric_limits<double>::infinity();
    REQUIRE_THROWS_WITH(checkParams(t, p, ParamSpelling::Flag, ""), "--region-threshold inf: must be finite");
    checkDeclaration(t, "scalp");
}

TEST_CASE("Parameters: render's declaration, the views and colourings by name, in docs/cli.md", "[params]")
{
    const ParamTable<RenderParams>& t = renderParameters();
    CHECK(declared(t, "view").defaultText() == viewName(RenderParams{}.view));
    CHECK(declared(t, "color-by").defaultText() == colorByName(RenderParams{}.colorBy));
    RenderParams p;
    setParam(t, "view", p, std::string("side"));
    setParam(t, "color-by", p, std::string("error"));
    setParam(t, "width", p, 300);
    setParam(t, "height", p, 200);
    CHECK(p.view == View::Side);
    CHECK(p.colorBy == ColorBy::Error);
    // What the renderer draws: an image of the declared size.
    StrandSet strands;
    strands.addStrand(std::vector<Vec3f>{Vec3f(0.f), Vec3f(0.f, 1.f, 0.f)});
    setParam(t, "color-by", p, std::string("root"));
    const Image image = renderStrands(strands, p);
    CHECK(image.width == 300);
    CHECK(image.height == 200);
    p.width = RenderParams::kMaxSize + 1;
    REQUIRE_THROWS_WITH(checkParams(t, p, ParamSpelling::Flag, ""), "--width 16385: must be between 1 and 16384 pixels");
    checkDeclaration(t, "render");
}

TEST_CASE("Parameters: compare's declaration sets what the comparison reads, in docs/cli.md", "[params]")
{
    const ParamTable<CompareParams>& t = compareParameters();
    CHECK(declared(t, "bidirectional").flag() == "--bidirectional");
    CompareParams p;
    setParam(t, "bidirectional", p, true);
    setParam(t, "samples", p, std::uint64_t(20));
    CHECK(p.bidirectional);
    CHECK(p.samples == 20);
    p.samples = 2;
    REQUIRE_THROWS_WITH(checkParams(t, p, ParamSpelling::Flag, ""), "--samples 2: must be at least 3");
    checkDeclaration(t, "compare");
}

TEST_CASE("Parameters: convert's declaration, the axes and the write options by name, in docs/cli.md", "[params]")
{
    const ParamTable<ConvertParams>& t = convertParameters();
    CHECK(declared(t, "up").defaultText() == "y");
    CHECK(declared(t, "usd-up").defaultText() == "auto");
    CHECK(declared(t, "usd-up").pythonNone);
    CHECK(declared(t, "codec").defaultText() == positionCodecName(WriteOptions{}.vdb.codec));
    ConvertParams p;
    setParam(t, "up", p, std::string("-z"));
    setParam(t, "usd-up", p, std::string("z"));
    setParam(t, "ply-encoding", p, std::string("ascii"));
    setParam(t, "obj-lines", p, std::string("polylines"));
    setParam(t, "codec", p, std::string("fixed16"));
    setParam(t, "width", p, 0.25);
    CHECK(p.up == Vec3d(0.0, 0.0, -1.0));
    CHECK(p.write.usd.upAxis == "Z");
    CHECK(p.write.plyEncoding == PlyEncoding::Ascii);
    CHECK(p.write.objLines == ObjLineStyle::Polylines);
    CHECK(p.write.vdb.codec == PositionCodec::Fixed16);
    CHECK(p.write.usd.width == 0.25f);
    setParam(t, "usd-up", p, std::string("auto"));
    CHECK(p.write.usd.upAxis.empty());
    // The write options are writeParameters(), Python's write() keywords: the same declaration.
    for (const Param<WriteOptions>& w : writeParameters()) CHECK(paramHelp(declared(t, w.name)) == paramHelp(w));
    p = ConvertParams{};
    p.write.vdb.voxelSize = -1.0;
    REQUIRE_THROWS_WITH(checkParams(t, p, ParamSpelling::Flag, ""), "--voxel-size -1: must be at least 0 world units");
    p = ConvertParams{};
    p.write.usd.width = -1.f;
    REQUIRE_THROWS_WITH(checkParams(writeParameters(), p.write, ParamSpelling::Keyword, "write"), "write: width -1: must be at least 0 world units");
    checkDeclaration(t, "convert");
}

TEST_CASE("Parameters: prepare's declaration, a keyword that is not its name, in docs/cli.md", "[params]")
{
    const ParamTable<PrepareParams>& t = prepareParameters();
    CHECK(declared(t, "strands").pythonName() == "count");
    CHECK(declared(t, "root-depth").defaultText() == rootDepthName(PrepareParams{}.rootDepth));
    PrepareParams p;
    setParam(t, "strands", p, std::uint64_t(500));
    setParam(t, "points", p, std::uint64_t(32));
    setParam(t, "overlap", p, 0.5);
    setParam(t, "head-crop", p, 1.5);
    setParam(t, "root-depth", p, std::string("surface"));
    CHECK(p.strands == 500);
    CHECK(p.points == 32);
    CHECK(p.align.overlap == 0.5);
    CHECK(p.headCrop == 1.5);
    CHECK(p.rootDepth == RootDepth::Surface);
    p.align.overlap = 0.0;
    REQUIRE_THROWS_WITH(checkParams(t, p, ParamSpelling::Keyword, "prepare"), "prepare: overlap 0: must be above 0 and at most 1");
    checkDeclaration(t, "prepare");
}

TEST_CASE("Parameters: inspect's slice declaration, the colouring as a flag and the sizes' ranges, in docs/cli.md", "[params]")
{
    const ParamTable<SliceParams>& t = sliceParameters();
    CHECK(declared(t, "hsv").flag() == "--hsv");
    CHECK(declared(t, "hsv").defaultText() == "false");
    CHECK(declared(t, "width").defaultText() == std::to_string(SliceParams{}.width));
    CHECK(declared(t, "streamlines").defaultText() == std::to_string(SliceParams{}.streamlines));
    SliceParams p;
    setParam(t, "hsv", p, true);
    setParam(t, "streamlines", p, 300);
    setParam(t, "width", p, 400);
    CHECK(p.color == SliceColor::Hsv);
    CHECK(p.streamlines == 300);
    CHECK(p.width == 400);
    setParam(t, "hsv", p, false);
    CHECK(p.color == SliceColor::Rgb);
    p.width = SliceParams::kMinWidth - 1;
    REQUIRE_THROWS_WITH(checkParams(t, p, ParamSpelling::Flag, ""), "--width 15: must be between 16 and 16384 pixels");
    p = SliceParams{};
    p.streamlines = SliceParams::kMaxStreamlines + 1;
    REQUIRE_THROWS_WITH(checkParams(t, p, ParamSpelling::Keyword, "inspect"), "inspect: streamlines 100001: must be between 0 and 100000");
    // The renderer checks the same ranges, in the parameters' names.
    REQUIRE_THROWS_WITH(renderSlice("missing.vdb", "tangent", p), "inspect(missing.vdb): streamlines 100001: must be between 0 and 100000");
    // inspect's own declaration holds the slice's, behind the grid and the plane.
    const ParamTable<InspectParams>& it = inspectParameters();
    CHECK(declared(it, "slice").flag() == "--slice");
    CHECK(paramName(it, "grid").keyword == "grid");
    CHECK(declared(it, "width").defaultText() == std::to_string(SliceParams{}.width));
    checkDeclaration(it, "inspect");
}

TEST_CASE("inspectSlice: one rule for the slice and its image, spelled for each front end", "[params]")
{
    const auto both = [](const InspectParams& p, const std::string& output, const std::string& where) {
        try {
            (void)inspectSlice(p, output, where);
        } catch (const std::exception& e) {
            return std::make_pair(spelledMessage(e, ParamSpelling::Flag), spelledMessage(e, ParamSpelling::Keyword));
        }
        return std::make_pair(std::string(), std::string());
    };
    InspectParams p;
    p.slice = "z=0";
    CHECK(both(p, "", "") == std::make_pair(std::string("--slice z=0: needs -o, the slice image's path (.png, .exr, .jpg)"),
                                            std::string("slice z=0: needs output, the slice image's path (.png, .exr, .jpg)")));
    CHECK(both(p, "a.hair", "inspect").second == "inspect: output a.hair: not an image format OpenImageIO writes (use .png, .exr or .jpg)");
    p.slice = "y=abc";
    CHECK(both(p, "a.png", "").first == "--slice y=abc: expected AXIS=WORLD with AXIS x, y or z and WORLD a finite number (e.g. z=1.5)");
    p.slice = "y=-2.5";
    const SliceParams sp = inspectSlice(p, "a.png", "");
    CHECK(sp.axis == 1);
    CHECK(sp.world == -2.5);
    p.slice.clear();
    CHECK(both(p, "a.png", "").first == "-o a.png: an image is drawn only of a slice: add --slice AXIS=WORLD");
    p.draw.streamlines = 10;
    CHECK(both(p, "", "inspect").second == "inspect: hsv and streamlines draw on a slice: add slice AXIS=WORLD and output");
    CHECK(both(p, "", "").first == "--hsv and --streamlines draw on a slice: add --slice AXIS=WORLD and -o");
    p.draw.streamlines = 0;
    CHECK(both(p, "", "").first.empty());  // no slice, no image: the file described only
}

TEST_CASE("Parameters: info's statistics declaration, the histograms' bins, in docs/cli.md", "[params]")
{
    const ParamTable<StrandStatsParams>& t = strandStatsParameters();
    CHECK(declared(t, "bins").defaultText() == std::to_string(kDefaultHistogramBins));
    StrandStatsParams p;
    setParam(t, "bins", p, std::uint64_t(7));
    CHECK(p.bins == 7);
    // What the statistics are made with: that many bins in every histogram.
    StrandSet strands;
    strands.addStrand(std::vector<Vec3f>{Vec3f(0.f), Vec3f(0.f, 1.f, 0.f), Vec3f(1.f, 1.f, 0.f)});
    CHECK(computeStrandStatistics(strands, p.bins).length.counts.size() == 7);
    p.bins = 0;
    REQUIRE_THROWS_WITH(checkParams(t, p, ParamSpelling::Flag, ""), "--bins 0: must be between 1 and 10000");
    p.bins = StrandStatsParams::kMaxBins + 1;
    REQUIRE_THROWS_WITH(checkParams(t, p, ParamSpelling::Keyword, "strand_statistics"), "strand_statistics: bins 10001: must be between 1 and 10000");
    REQUIRE_THROWS_WITH(computeStrandStatistics(strands, 0), "computeStrandStatistics: bins 0: must be between 1 and 10000");
    checkDeclaration(t, "info");
}

TEST_CASE("Parameters: what synth, transfer, comb, field and refine share is declared once", "[params]")
{
    // The axes, refinement, measuring: synth's declaration, nested into transfer (and comb's up).
    for (const char* name : {"up", "front", "refine"}) {
        CAPTURE(name);
        REQUIRE(findParam(transferParameters(), name));
        CHECK(paramHelp(*findParam(transferParameters(), name)) == paramHelp(*findParam(synthParameters(), name)));
    }
    CHECK(paramHelp(*findParam(combParameters(), "up")) == paramHelp(*findParam(synthParameters(), "up")));
    CHECK(findParam(combParameters(), "front") == nullptr);
    CHECK(findParam(synthParameters(), "refine")->flag() == "--no-refine");
    CHECK(findParam(transferParameters(), "smooth-base")->flag() == "--no-smooth-base");
    CHECK(findParam(transferParameters(), "smooth-base")->oldFlags == std::vector<std::string>{"--keep-base-detail"});
    // The output turn: degrees in both front ends, radians in the library.
    SynthParams sp;
    setParam(synthParameters(), "output-turn", sp, 90.0);
    CHECK(sp.outputTurn == Approx(M_PI / 2.0).margin(1e-15));
    setParam(synthParameters(), "up", sp, Vec3d(0.0, 0.0, 1.0));
    CHECK(sp.up == Vec3d(0.0, 0.0, 1.0));
    setParam(synthParameters(), "strands", sp, std::size_t(300));
    CHECK(sp.strands == 300);
    // One head policy for refine and comb (headPolicyParam()); refine's space and up are field's.
    CHECK(paramHelp(*findParam(combParameters(), "head-policy")) == paramHelp(*findParam(refineParameters(), "head-policy")));
    CombParams cp;
    setParam(combParameters(), "head-policy", cp, std::string("outside"));
    CHECK(cp.headPolicy == HeadPolicy::KeepOutside);
    for (const char* name : {"space", "up"}) {
        CAPTURE(name);
        CHECK(paramHelp(*findParam(refineParameters(), name)) == paramHelp(*findParam(fieldParameters(), name)));
        CHECK(findParam(refineParameters(), name)->defaultText() == findParam(fieldParameters(), name)->defaultText());
    }
    RefineParams rp;
    setParam(refineParameters(), "up", rp, Vec3d(0.0, 0.0, -1.0));
    setParam(refineParameters(), "space", rp, std::string("scalp"));
    CHECK(rp.field.scalp.up == Vec3d(0.0, 0.0, -1.0));
    CHECK(rp.field.space == FieldSpace::Scalp);
}

TEST_CASE("Parameters: batch's and demo's declarations (the command line's own verbs), in docs/cli.md", "[params]")
{
    using app::BatchParams;
    const ParamTable<BatchParams>& b = app::batchParameters();
    CHECK(declared(b, "jobs").defaultText() == std::to_string(BatchParams{}.jobs));
    CHECK(declared(b, "jobs").flag() == "--jobs");
    CHECK(declared(b, "retry-failed").flag() == "--retry-failed");
    BatchParams p;
    p.jobs = -1;
    REQUIRE_THROWS_WITH(checkParams(b, p, ParamSpelling::Flag, ""), "--jobs -1: must be at least 0");
    checkDeclaration(b, "batch");
    // demo: refine's declaration but --measure (the demo always measures).
    const ParamTable<RefineParams>& d = app::demoParameters();
    CHECK(d.size() + 1 == refineParameters().size());
    CHECK(findParam(d, "measure") == nullptr);
    CHECK(declared(d, "levels").defaultText() == declared(refineParameters(), "levels").defaultText());
    checkDeclaration(d, "demo");
}

TEST_CASE("Parameters: a library error names its parameters, each front end spells them (ParamError)", "[params]")
{
    // Rules the declared ranges cannot say, checked by the library itself.
    FitParams fp;
    fp.step = -1.0;
    try {
        fp.validate("fit");
        FAIL("FitParams::validate accepted step -1");
    } catch (const ValueError& e) {
        CHECK(spelledMessage(e, ParamSpelling::Flag) == "fit: --step -1: must be a positive finite length (0: a quarter of the mean segment length)");
        CHECK(std::string(e.what()) == "fit: step -1: must be a positive finite length (0: a quarter of the mean segment length)");
    }
    fp = FitParams{};
    fp.lambda = -1.0;
    try {
        fp.validate("fit");
        FAIL("FitParams::validate accepted lambda -1");
    } catch (const ValueError& e) {
        CHECK(spelledMessage(e, ParamSpelling::Flag) == "fit: --lambda -1: must be zero or positive");
        CHECK(spelledMessage(e, ParamSpelling::Keyword) == "fit: lambda_ -1: must be zero or positive");
    }
    SynthParams sp;
    sp.match.balance = 0.5;
    try {
        sp.match.validate("transfer");
        FAIL("DetailMatchParams::validate accepted a balance of 0.5");
    } catch (const ValueError& e) {
        CHECK(spelledMessage(e, ParamSpelling::Flag) == "transfer: --match-balance 0.5: 0 (off) or a finite factor of at least 1");
        CHECK(spelledMessage(e, ParamSpelling::Keyword) == "transfer: match_balance 0.5: 0 (off) or a finite factor of at least 1");
    }
    RefineParams rp;
    rp.consistency.zFull = rp.consistency.zStart;
    try {
        rp.validate("refine");
        FAIL("RefineParams::validate accepted an outlier full no higher than its start");
    } catch (const ValueError& e) {
        CHECK_THAT(spelledMessage(e, ParamSpelling::Flag), Contains("refine: --outlier-full 2: must be finite and above --outlier-start 2"));
        CHECK_THAT(e.what(), Contains("refine: outlier_full 2: must be finite and above outlier_start 2"));
    }
    // The readers' options, in Python's spelling (read()'s keywords) unless told otherwise.
    try {
        rootEndFromName("tip");
        FAIL("rootEndFromName accepted tip");
    } catch (const ValueError& e) {
        CHECK(spelledMessage(e, ParamSpelling::Flag) == "--roots 'tip': must be first, last or auto");
        CHECK(std::string(e.what()) == "roots='tip': must be first, last or auto");
    }
    // ParamText keeps its parts apart.
    const ParamText text{"a ", ParamName{"--x", "x_"}, " b"};
    CHECK(text.spelled(ParamSpelling::Flag) == "a --x b");
    CHECK(text.spelled(ParamSpelling::Keyword) == "a x_ b");
}
