// The command's options against the library's parameter structs: every default `--help` shows
// is the struct's, every range the command checks is the library's named limit, and the
// library's parameter names in messages become the verb's flags. A default restated in a
// command (a literal beside the struct's member initializer) fails here as soon as they differ.
#include "../TestUtil.h"

#include "Command.h"

#include <vdbhair/dataset/Prepare.h>
#include <vdbhair/strands/StrandStats.h>
#include <vdbhair/Exceptions.h>
#include <vdbhair/field/HeadObstacle.h>
#include <vdbhair/field/Refine.h>
#include <vdbhair/field/Streamline.h>
#include <vdbhair/field/TangentField.h>
#include <vdbhair/helicoid/HelicoidFit.h>
#include <vdbhair/helicoid/HelicoidInterpolation.h>
#include <vdbhair/helicoid/PointInterpolation.h>
#include <vdbhair/helicoid/Reconstruction.h>
#include <vdbhair/helicoid/Scene.h>
#include <vdbhair/io/StrandIO.h>
#include <vdbhair/render/SliceRenderer.h>
#include <vdbhair/render/StrandRenderer.h>
#include <vdbhair/scalp/Follicles.h>
#include <vdbhair/scalp/ScalpRegion.h>
#include <vdbhair/scalp/ScalpSurface.h>
#include <vdbhair/synth/Comb.h>
#include <vdbhair/synth/HairTransfer.h>
#include <vdbhair/synth/Synthesis.h>

#include <CLI/CLI.hpp>

#include <algorithm>
#include <string>
#include <vector>

using namespace vdbhair;
using namespace vdbhair::app;

namespace {

/// Every verb registered as `vdbhair` registers them.
struct Verbs
{
    CLI::App app{"vdbhair"};
    CommonOptions common;
    std::vector<Command> commands = addCommands(app, common);

    const Command& command(const std::string& verb) const
    {
        for (const Command& c : commands) if (c.sub->get_name() == verb) return c;
        FAIL("no verb " << verb);
        throw std::logic_error("unreachable");
    }
    /// What `vdbhair <verb> --help` shows as the default of @a flag ("" for none).
    std::string shown(const std::string& verb, const std::string& flag) const
    {
        return command(verb).sub->get_option(flag)->get_default_str();
    }
    /// Parse `vdbhair <args...>` and run the verb.
    int run(std::vector<std::string> args)
    {
        std::vector<std::string> reversed(args.rbegin(), args.rend());  // CLI11 parses a vector from the back
        app.parse(reversed);
        for (const Command& c : commands) if (c.sub->parsed()) return c.run();
        FAIL("no verb parsed");
        return -1;
    }
};

/// A value as CLI11 shows a default (capture_default_str()).
template<typename T>
std::string shownAs(const T& value)
{
    return CLI::detail::to_string(value);
}

} // namespace

TEST_CASE("vdbhair --help: every default is the library's", "[apps]")
{
    const Verbs v;
    struct Row
    {
        std::string verb, flag, expected;
    };
    const FieldParams field;
    const TraceParams trace;
    const RefineParams refine;
    const FitParams fit;
    const HelicoidInterpolationParams interp;
    const ReconstructParams rec;
    const FollicleParams follicles;
    const ScalpParams scalp;
    const SliceParams slice;
    const RenderParams render;
    const SynthParams synth;
    const TransferParams transfer;
    const CombParams comb;
    const std::vector<Row> rows = {
        {"field", "--iterations", shownAs(field.iterations)},
        {"field", "--max-voxels", shownAs(field.maxVoxels)},
        {"retrace", "--integrator", integratorName(trace.integrator)},
        {"retrace", "--vanish", shownAs(trace.vanishThreshold)},
        {"retrace", "--max-steps", shownAs(trace.maxSteps)},
        {"retrace", "--margin", shownAs(trace.margin)},
        {"retrace", "--vertices", trace.vertices == RetraceVertices::Input ? "input" : "steps"},
        {"refine", "--levels", shownAs(refine.levels)},
        {"refine", "--mode", refineModeName(refine.mode)},
        {"refine", "--iterations", shownAs(refine.field.iterations)},
        {"refine", "--outlier-start", shownAs(refine.consistency.zStart)},
        {"refine", "--outlier-full", shownAs(refine.consistency.zFull)},
        {"refine", "--min-spread", shownAs(refine.consistency.minSpreadDeg)},
        {"refine", "--integrator", integratorName(refine.trace.integrator)},
        {"refine", "--margin", shownAs(refine.trace.margin)},
        {"refine", "--max-voxels", shownAs(refine.field.maxVoxels)},
        {"refine", "--head-policy", headPolicyName(kDefaultHeadPolicy)},
        {"demo", "--levels", shownAs(refine.levels)},
        {"grow", "--max-vertices", shownAs(GrowOptions().maxVertices)},
        {"fit", "--max-error", shownAs(fit.maxError)},
        {"fit", "--lambda", shownAs(fit.lambda)},
        {"fit", "--max-pieces", shownAs(fit.maxPieces)},
        {"fit", "--max-evaluations", shownAs(fit.maxEvaluations)},
        {"interpolate", "--power", shownAs(interp.shepard.power)},
        {"interpolate", "--max-vertices", shownAs(interp.maxVertices)},
        {"interpolate", "--up", axisName(interp.up)},
        {"reconstruct", "--guides", formatNumber(100.0 * rec.guideFraction) + "%"},
        {"reconstruct", "--seed", shownAs(rec.seed)},
        {"reconstruct", "--power", shownAs(rec.helicoid.shepard.power)},
        {"reconstruct", "--max-error", shownAs(rec.fit.maxError)},
        {"roots", "--seed", shownAs(follicles.seed)},
        {"roots", "--iterations", shownAs(follicles.maxIterations)},
        {"roots", "--step-scale", shownAs(follicles.stepScale)},
        {"roots", "--up", axisName(follicles.up)},
        {"scalp", "--half-width", shownAs(scalp.halfWidth)},
        {"scalp", "--max-voxels", shownAs(scalp.maxVoxels)},
        {"scalp", "--max-constraints", shownAs(ScalpParams{}.maxConstraints)},
        {"scalp", "--region-threshold", shownAs(kDefaultRegionThreshold)},
        {"inspect", "--width", shownAs(slice.width)},
        {"inspect", "--streamlines", shownAs(slice.streamlines)},
        {"render", "--view", viewName(render.view)},
        {"render", "--width", shownAs(render.width)},
        {"render", "--height", shownAs(render.height)},
        {"render", "--color-by", colorByName(render.colorBy)},
        {"render", "--up", axisName(render.up)},
        {"render", "--grid", ReadOptions().vdbGrid},
        {"prepare", "--points", shownAs(PrepareParams().points)},
        {"prepare", "--strands", shownAs(PrepareParams().strands)},
        {"prepare", "--overlap", shownAs(PrepareParams().align.overlap)},
        {"prepare", "--head-crop", shownAs(PrepareParams().headCrop)},
        {"prepare", "--target-up", axisName(PrepareParams().targetUp)},
        {"prepare", "--root-depth", rootDepthName(PrepareParams().rootDepth)},
        {"info", "--bins", shownAs(kDefaultHistogramBins)},
        {"convert", "--grid", ReadOptions().vdbGrid},
        {"convert", "--codec", positionCodecName(WriteOptions().vdb.codec)},
        {"convert", "--meters-per-unit", shownAs(WriteOptions().usd.metersPerUnit)},
        {"synth", "--levels", shownAs(synth.cluster.levels)},
        {"synth", "--seed", shownAs(synth.seed)},
        {"synth", "--vertices", shownAs(synth.vertices)},
        {"synth", "--threshold", shownAs(synth.cluster.threshold)},
        {"synth", "--initial-clusters", shownAs(synth.cluster.initialClusters)},
        {"synth", "--components", shownAs(synth.components)},
        {"synth", "--map-spacing", shownAs(synth.mapSpacing)},
        {"synth", "--place-weight", shownAs(synth.placeWeight)},
        {"synth", "--nearby", shownAs(synth.texture.nearbyRadius)},
        {"synth", "--voxel-size", shownAs(synth.voxelSize)},
        {"synth", "--detail", std::string(detailBlendName(synth.detailBlend))},
        {"synth", "--detail-scale", std::string(detailScaleName(synth.detailScale))},
        {"synth", "--match-balance", shownAs(synth.match.balance)},
        {"synth", "--match-candidates", shownAs(synth.match.candidates)},
        {"synth", "--match-place", shownAs(synth.match.place)},
        {"synth", "--root-density", std::string(synth.exampleDensity ? "example" : "even")},
        {"transfer", "--detail-scale", std::string(detailScaleName(transfer.synth.detailScale))},
        {"transfer", "--match-balance", shownAs(transfer.synth.match.balance)},
        {"transfer", "--match-candidates", shownAs(transfer.synth.match.candidates)},
        {"transfer", "--match-place", shownAs(transfer.synth.match.place)},
        {"transfer", "--smoothing", shownAs(transfer.smoothing)},
        {"transfer", "--levels", shownAs(transfer.synth.cluster.levels)},
        {"comb", "--smoothing", shownAs(comb.smoothing)},
        {"comb", "--levels", shownAs(comb.synth.cluster.levels)},
    };
    for (const Row& r : rows) {
        CAPTURE(r.verb, r.flag);
        CHECK(v.shown(r.verb, r.flag) == r.expected);
    }
    // The help of a default the library computes names the library's rule.
    CHECK_THAT(v.command("retrace").sub->get_option("--step")->get_description(),
               Catch::Contains(formatValue(kDefaultStepVoxels) + " of the field's voxel size"));
}

TEST_CASE("vdbhair --help: the options both front ends take, declared once, show the library's defaults", "[apps]")
{
    const Verbs v;
    const SynthParams synth;
    const TransferParams transfer;
    const CombParams comb;
    const FieldParams field;
    const RefineParams refine;
    struct Row
    {
        std::string verb, flag, expected;
    };
    const std::vector<Row> rows = {
        // Axes by name, "auto" for the library's choice.
        {"synth", "--strands", shownAs(synth.strands)},
        {"synth", "--up", "auto"},
        {"synth", "--front", "auto"},
        {"synth", "--output-turn", shownAs(synth.outputTurn)},
        {"transfer", "--strands", shownAs(transfer.strands)},
        {"transfer", "--up", "auto"},
        {"transfer", "--front", "auto"},
        {"comb", "--up", "auto"},
        {"comb", "--head-policy", headPolicyName(comb.headPolicy)},
        {"field", "--levels", shownAs(FieldLevelsParams().levels)},
        {"field", "--space", fieldSpaceName(field.space)},
        {"field", "--up", axisName(field.scalp.up)},
        {"refine", "--space", fieldSpaceName(refine.field.space)},
        {"refine", "--up", axisName(refine.field.scalp.up)},
        {"demo", "--head-policy", headPolicyName(refine.headPolicy)},
        {"render", "--facing", "auto"},
    };
    for (const Row& r : rows) {
        CAPTURE(r.verb, r.flag);
        CHECK(v.shown(r.verb, r.flag) == r.expected);
    }
    // Switches (flags; --no-NAME turns off what is on by default), older spellings kept.
    for (const auto& [verb, flag] : std::vector<std::pair<std::string, std::string>>{
             {"synth", "--no-refine"}, {"transfer", "--no-refine"}, {"transfer", "--no-smooth-base"}, {"transfer", "--keep-base-detail"},
             {"compare", "--no-pair-strands"}, {"compare", "--unpaired"}, {"fit", "--skip-degenerate"}, {"render", "--sheet"}}) {
        CAPTURE(verb, flag);
        CHECK(v.command(verb).sub->get_option_no_throw(flag) != nullptr);
    }
}

TEST_CASE("vdbhair: range checks are the library's limits", "[apps]")
{
    const std::string missing = test::tempPath("defaults_missing.hair");
    const std::string out = test::tempPath("defaults_out.vdb");
    // One past a limit is refused before any file is read; the limit itself passes the checks
    // and fails only on the missing input.
    {
        Verbs v;
        REQUIRE_THROWS_WITH(v.run({"field", missing, "-o", out, "--levels", std::to_string(FieldParams::kMaxLevels + 1)}),
                            Catch::Contains("--levels " + std::to_string(FieldParams::kMaxLevels + 1) + ": must be between 1 and " +
                                            std::to_string(FieldParams::kMaxLevels)));
    }
    {
        Verbs v;
        REQUIRE_THROWS_AS(v.run({"field", missing, "-o", out, "--levels", std::to_string(FieldParams::kMaxLevels)}), IoError);
    }
    const std::string field = test::tempPath("defaults_missing.vdb"), traced = test::tempPath("defaults_out.hair");
    {
        Verbs v;
        REQUIRE_THROWS_WITH(v.run({"retrace", missing, "--field", field, "-o", traced, "--margin", std::to_string(TraceParams::kMaxMargin + 1)}),
                            Catch::Contains("must be between 0 and " + std::to_string(TraceParams::kMaxMargin)));
    }
    {
        Verbs v;
        REQUIRE_THROWS_AS(v.run({"retrace", missing, "--field", field, "-o", traced, "--margin", std::to_string(TraceParams::kMaxMargin)}),
                          IoError);
    }
}

TEST_CASE("ParamError: the library names parameters, the command line spells them as flags", "[apps]")
{
    // What the library throws, as run() prints it (spelledMessage(e, ParamSpelling::Flag)).
    SliceParams sp;
    sp.width = SliceParams::kMaxWidth + 1;
    try {
        renderSlice("missing.vdb", "tangent", sp);
        FAIL("renderSlice accepted a width beyond SliceParams::kMaxWidth");
    } catch (const ValueError& e) {
        CHECK_THAT(spelledMessage(e, ParamSpelling::Flag), Catch::Contains("--width " + std::to_string(sp.width) + ": must be between"));
        CHECK_THAT(e.what(), Catch::Contains(": width " + std::to_string(sp.width) + ": must be between"));
    }
    try {
        colorByFromName("plaid");
        FAIL("colorByFromName accepted plaid");
    } catch (const ValueError& e) {
        CHECK(spelledMessage(e, ParamSpelling::Flag) == "--color-by 'plaid' is not one of shaded, root, tangent, depth, curvature, strand, error");
        CHECK(spelledMessage(e, ParamSpelling::Keyword) == "color_by 'plaid' is not one of shaded, root, tangent, depth, curvature, strand, error");
    }
    // An error that names no parameter is its what() in either spelling.
    const IoError plain("a.hair: cannot open");
    CHECK(spelledMessage(plain, ParamSpelling::Flag) == "a.hair: cannot open");
}
