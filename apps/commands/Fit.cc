// vdbhair fit IN -o FITS.json: p-helicoids fitted to every strand (Piuze et al. 2011, §5).
#include "../Command.h"
#include "../ParamOptions.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/helicoid/HelicoidFit.h>
#include <vdbhair/helicoid/HelicoidJson.h>
#include <vdbhair/helicoid/Scene.h>
#include <vdbhair/io/FileUtil.h>

#include <algorithm>
#include <chrono>
#include <cmath>

namespace vdbhair::app {

namespace {

struct FitCmdParams
{
    std::string input, output;
    FitParams fit;  ///< its declared parameters (fitParameters()) are options
};

int runFit(FitCmdParams p, const CommonOptions& common)
{
    if (fileExtension(p.output) != ".json") throw ValueError(p.output + ": fits are written as a scene file; the output must end in .json");
    checkParamOptions(fitParameters(), p.fit);
    p.fit.validate("option");  // the library's own rules (ParamErrors: run() spells them as flags)
    const StrandSet strands = loadStrands("fit", p.input, common);

    const auto t0 = std::chrono::steady_clock::now();
    std::vector<std::string> errors;
    const std::vector<StrandFit> fits = fitStrands(strands, p.fit, true, &errors, common.interrupter);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

    Scene scene;
    scene.integrator = HelicoidIntegrator::RK4;  // fits are streamlines, regrown exactly
    for (std::size_t i = 0; i < fits.size(); ++i) {
        if (!errors[i].empty()) {
            if (!p.fit.skipDegenerate) throw ValueError(p.input + ": " + errors[i] + " (--skip-degenerate leaves such strands out)");
            if (!common.quiet) std::cerr << "vdbhair fit: warning: skipped " << errors[i] << "\n";
            continue;
        }
        const StrandFit& f = fits[i];
        SceneGuide g = guideFromFit(f);
        g.fit = {{"frechet", f.frechet}, {"coupling", f.coupling}, {"pieces", f.pieces.size()}, {"strand", i},
                 {"step_deviation", f.stepDeviation}};
        scene.guides.push_back(g);
    }
    if (scene.guides.empty()) throw ValueError(p.input + ": no strand could be fitted");
    writeScene(p.output, scene);

    // Summary: errors relative to strand length, pieces, and how much smaller the fit is.
    const FitSummary s = summarizeFits(strands, fits, errors, p.fit.maxError, p.fit.stepDeviationLimit);
    if (s.overMaxError && !common.quiet) {
        std::cerr << "vdbhair fit: warning: " << s.overMaxError << " of " << s.fitted << " fits end above --max-error "
                  << formatValue(p.fit.maxError) << " (a last piece takes what remains at the most pieces a strand may have, or under twice the shortest fragment)\n";
    }
    if (s.unconverged && !common.quiet) {
        std::cerr << "vdbhair fit: warning: " << s.unconverged << " of " << s.fitted << " fits move by more than " << formatValue(p.fit.stepDeviationLimit) << " of --max-error when traced at a quarter of their step "
                  << "(largest: " << formatValue(100.0 * s.stepDeviationMax) << " % of the strand's length); they pass near a piece's singular axis\n";
    }
    if (common.json) {
        nlohmann::json j = fitReport(s);
        j["output"] = p.output;
        j["strands_per_second"] = double(s.fitted) / seconds;
        printJson(j);
    } else if (!common.quiet) {
        std::cout << "fitted " << s.fitted << " of " << s.strands << " strands with " << s.piecesPerStrand << " pieces each on average in "
                  << seconds << " s (" << double(s.fitted) / seconds << " strands/s)\n"
                  << "discrete Frechet distance relative to strand length: mean " << s.meanRelative << ", 95th percentile " << s.p95Relative << "\n"
                  << "step convergence (trace at the step against a quarter of it, relative to strand length): mean " << s.stepDeviationMean
                  << ", largest " << s.stepDeviationMax << "\n"
                  << "size: " << s.fitBytes << " bytes of helicoid parameters for " << s.pointBytes << " bytes of points ("
                  << s.pointBytes / s.fitBytes << "x smaller)\nwrote " << p.output << " (regrow it with 'vdbhair grow')\n";
    }
    return 0;
}

} // namespace

Command addFitCommand(CLI::App& app, CommonOptions& common)
{
    auto params = std::make_shared<FitCmdParams>();
    CLI::App* sub = addVerb(app, "fit");
    sub->add_option("input", params->input, "Strand file")->required();
    sub->add_option("-o,--output", params->output, "Scene file (.json): one guide per input strand, in input order")->required();
    addParamOptions(sub, params->fit, fitParameters());
    addStrictOption(sub, common);
    addCommonOptions(sub, common);
    addReadOptions(sub, common);
    sub->footer("Example: vdbhair fit hair.hair -o fits.json --json && vdbhair grow fits.json -o regrown.hair");
    return {sub, [params, &common] { return runFit(*params, common); }};
}

} // namespace vdbhair::app
