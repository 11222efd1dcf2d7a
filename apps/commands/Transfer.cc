// vdbhair transfer DETAILS BASE -o OUT: BASE's coarsest level with DETAILS' finer levels (Wang et
// al. 2009, §6), and `synth EXAMPLE --coarse BASE`, which is the same operation.
#include "../Command.h"
#include "../HeadOptions.h"
#include "../ParamOptions.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/compare/HairComparison.h>
#include <vdbhair/io/StrandIO.h>
#include <vdbhair/scalp/ScalpSurface.h>
#include <vdbhair/synth/HairTransfer.h>
#include <vdbhair/synth/SynthJson.h>

#include <algorithm>
#include <chrono>
#include <cstdio>

namespace vdbhair::app {

namespace {

struct TransferCmdParams
{
    TransferJob job = [] { TransferJob j; j.verb = "transfer"; return j; }();
    TransferParams params;  ///< its declared parameters (transferParameters()) are options
    std::string head;  ///< --head: a file, "none", or empty for BASE's (its scalp, else the sphere fitted to its roots)
};

} // namespace

int runTransferJob(const TransferJob& job, TransferParams params, const CommonOptions& common)
{
    strandFormatFromPath(job.output, /*forWriting=*/true);
    params.validate("option");
    const StrandSet details = loadStrandsOrScene(job.verb, job.details, common);
    const StrandSet base = loadStrandsOrScene(job.verb, job.base, common);
    if (details.empty()) throw ValueError(job.details + ": no strands to take detail from");
    if (base.empty()) throw ValueError(job.base + ": no strands to transfer onto");
    const openvdb::FloatGrid::Ptr scalp = readScalpOption(job.scalp, common);
    const auto t0 = std::chrono::steady_clock::now();
    TransferResult tr;
    try {
        const Stage stage(common, "transferring detail");
        tr = transferHairstyle(details, base, params, scalp, true, common.interrupter);
    } catch (const ValueError& e) {
        // The library names the hairstyles DETAILS and BASE; the message names the files.
        std::string what = spelledMessage(e, ParamSpelling::Flag);
        const auto name = [&](const std::string& word, const std::string& by) {
            for (std::size_t at = what.find(word); at != std::string::npos; at = what.find(word, at + by.size())) what.replace(at, word.size(), by);
        };
        name("DETAILS", job.detailsLabel + " (" + job.details + ")");
        name("BASE", job.baseLabel + " (" + job.base + ")");
        throw ValueError(what);
    }
    const SynthResult& r = tr.result;
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    {
        const Stage stage(common, "writing " + job.output);
        writeSynthStrands(job.output, r.strands, r.clusterOf);
    }
    // What the transfer did (docs/editing.md, says why each check): only
    // measured to be printed.
    if (common.quiet && !common.json) return 0;
    TransferMeasures m;
    {
        const Stage stage(common, params.synth.measure ? "measuring the output, comparing with the base" : "measuring the output");
        m = measureTransfer(details, base, tr, params, params.synth.measure);
    }
    const double rd = tr.detailsMap->radius(), rb = r.map->radius();
    if (common.json) {
        nlohmann::json j = transferReport(base, tr, params, m);
        j["output"] = job.output;
        j["details"] = job.details;
        j["base"] = job.base;
        j["seconds"] = seconds;
        printJson(j);
    } else if (!common.quiet) {
        std::cout << "transferred the detail of " << job.details << " (" << details.numStrands() << " strands) onto "
                  << job.base << " (" << base.numStrands() << "): " << r.strands.numStrands() << " strands in " << seconds << " s\n"
                  << "  turning per head radius: details " << m.turnDetails * rd << ", base " << m.turnBase * rb << ", output " << m.turnOut * rb << "\n"
                  << "  curl amplitude (head radii): details " << m.curlDetails << ", base " << m.curlBase << ", output " << m.curlOut << "\n"
                  << "  output wisps from the base's coarsest strands: " << m.deviationMean * 100.0 << " % of their length (mean)\n"
                  << "  wisp length ratio base/details " << tr.lengthRatio << ", detail scale " << tr.detailScale << "\n";
        if (r.head != "none") {
            char shares[128];
            std::snprintf(shares, sizeof shares, "%.1f %% of the output, %.1f %% of the base",
                          100.0 * double(r.enteringHead) / double(std::max<std::size_t>(1, r.strands.numStrands())), 100.0 * double(r.exampleEnteringHead) / double(base.numStrands()));
            std::cout << "  head: " << r.head << " (no new vertex deeper than its root); " << r.headPushedOut << " strands pushed out; passing into it: " << shares << "\n";
        }
        std::cout << "  by region, output (base):\n" << m.regionText;
        if (m.measured) std::cout << "  compared with " << job.base << " (vdbhair compare): " << summaryLine(m.comparison) << "\n";
        std::cout << "wrote " << job.output << "\n";
    }
    return 0;
}

Command addTransferCommand(CLI::App& app, CommonOptions& common)
{
    auto p = std::make_shared<TransferCmdParams>();
    CLI::App* sub = addVerb(app, "transfer");
    sub->add_option("details", p->job.details, "The hairstyle whose detail is taken (any strand format, or a scene)")->required();
    sub->add_option("base", p->job.base, "The hairstyle whose coarsest level is kept (any strand format, or a scene)")->required();
    sub->add_option("-o,--output", p->job.output, "The result (any strand format; .vdb points also carry int cluster_level_1.. attributes)")->required();
    sub->add_option("--scalp", p->job.scalp, "BASE's scalp: a .vdb with a level set 'surface' or a head mesh; default: the sphere fitted to BASE's roots");
    addParamOptions(sub, p->params, transferParameters());
    sub->add_option("--head", p->head, "The head new hair may enter no deeper than BASE's hair: a mesh (.ply, .obj), a .vdb level set, or 'none' "
                                       "(default: --scalp's surface, else the sphere fitted to BASE's roots)");
    addCommonOptions(sub, common);
    addReadOptions(sub, common);
    sub->footer("Example: vdbhair transfer curly.hair straight.hair -o curly_straight.hair --json");
    return {sub, [p, &common] {
                TransferParams params = p->params;
                checkParamOptions(transferParameters(), params);
                if (params.strands > 0 && !params.guides) throw ValueError("--strands: the output has BASE's strands; --strands needs --guides");
                params.synth.head = headFromOptions(HeadOptions{p->head}, params.synth.head);
                return runTransferJob(p->job, params, common);
            }};
}

} // namespace vdbhair::app
