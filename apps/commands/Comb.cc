// vdbhair comb IN --stroke STROKE.json -o OUT: detail-preserving combing (Wang et al. 2009, §6).
#include "../Command.h"
#include "../HeadOptions.h"
#include "../ParamOptions.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/io/StrandIO.h>
#include <vdbhair/scalp/ScalpSurface.h>
#include <vdbhair/synth/Comb.h>
#include <vdbhair/synth/SynthJson.h>

#include <chrono>

namespace vdbhair::app {

namespace {

struct CombCmdParams
{
    std::string input, output, stroke, scalp;
    CombParams params;  ///< its declared parameters (combParameters()) are options
    HeadOptions head;
};

int runComb(CombCmdParams p, const CommonOptions& common)
{
    strandFormatFromPath(p.output, /*forWriting=*/true);
    checkParamOptions(combParameters(), p.params);
    p.params.validate("option");
    const std::vector<CombStroke> strokes = readStrokes(p.stroke);
    const StrandSet in = loadStrandsOrScene("comb", p.input, common);
    if (in.empty()) throw ValueError(p.input + ": no strands to comb");
    const openvdb::FloatGrid::Ptr scalp = readScalpOption(p.scalp, common);
    p.head.policy = &p.params.headPolicy;
    p.params.head = headFromOptions(p.head);
    const auto t0 = std::chrono::steady_clock::now();
    CombResult r;
    {
        const Stage stage(common, "combing");
        try {
            r = combHair(in, strokes, p.params, scalp, true, common.interrupter);
        } catch (const ValueError& e) {
            throw ValueError(p.input + ": " + spelledMessage(e, ParamSpelling::Flag));
        }
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    {
        const Stage stage(common, "writing " + p.output);
        writeStrands(p.output, r.strands);
    }
    const CombStats& s = r.stats;
    if (s.combedClusters == 0 && !common.quiet)
        std::cerr << "vdbhair comb: warning: no stroke reaches a wisp of " << p.input << "; the output equals the input\n";
    if (common.json) {
        nlohmann::json j = combReport(r, strokes.size());
        j["output"] = p.output;
        j["input"] = p.input;
        j["seconds"] = seconds;
        printJson(j);
    } else if (!common.quiet) {
        std::cout << "combed " << s.movedStrands << " of " << r.strands.numStrands() << " strands (" << s.combedClusters << " of "
                  << s.clusters << " wisps) with " << strokes.size() << " stroke" << (strokes.size() == 1 ? "" : "s") << " in "
                  << seconds << " s\n"
                  << "  angle to the stroke within its reach: " << s.angleBefore << " -> " << s.angleAfter << " degrees\n"
                  << "  turning per length of the moved strands: " << s.turningBefore << " -> " << s.turningAfter << "\n"
                  << "  moved strands with a new turn over " << kKinkDegrees << " degrees between two edges: " << s.newKinks
                  << " (" << s.backedOff << " combed less than their wisp to avoid one)\n"
                  << "  head: " << s.head << "; " << s.headDeflected << " strands pushed out of it, moved vertices inside it "
                  << s.insideHeadBefore << " -> " << s.insideHeadAfter << "\n"
                  << "wrote " << p.output << "\n";
    }
    return 0;
}

} // namespace

Command addCombCommand(CLI::App& app, CommonOptions& common)
{
    auto p = std::make_shared<CombCmdParams>();
    CLI::App* sub = addVerb(app, "comb");
    sub->add_option("input", p->input, "The hairstyle (any strand format, or a scene)")->required();
    sub->add_option("--stroke", p->stroke, "Strokes, JSON: {\"strokes\": [{\"points\": [[x,y,z], ...], \"radius\": R, \"strength\": S}]} (world units; strength 0-1, default 1), applied in order")->required();
    sub->add_option("-o,--output", p->output, "The combed hairstyle (any strand format)")->required();
    sub->add_option("--scalp", p->scalp, "The scalp: a .vdb with a level set 'surface' or a head mesh; default: the sphere fitted to the roots");
    addParamOptions(sub, p->params, combParameters());
    addHeadOptions(sub, p->head, p->params.headPolicy, "--scalp's level set if given, else a sphere fitted to the roots");
    addCommonOptions(sub, common);
    addReadOptions(sub, common);
    sub->footer("Example: vdbhair comb scenes/default/head.json --stroke scenes/comb/sweep_ponytail.json -o combed.hair --json");
    return {sub, [p, &common] { return runComb(*p, common); }};
}

} // namespace vdbhair::app
