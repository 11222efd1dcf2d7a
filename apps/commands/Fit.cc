// vdbhair fit IN -o FITS.json: p-helicoids fitted to every strand (Piuze et al. 2011, §5).
#include "../Command.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/helicoid/HelicoidFit.h>
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
    FitParams fit;
    bool skipDegenerate = false;
    bool strict = false;
};

int runFit(FitCmdParams p, const CommonOptions& common)
{
    if (fileExtension(p.output) != ".json") throw ValueError(p.output + ": fits are written as a scene file; the output must end in .json");
    if (!(p.fit.maxError > 0.0) || !std::isfinite(p.fit.maxError)) throw ValueError("--max-error " + formatValue(p.fit.maxError) + ": must be a positive fraction of the strand length");
    if (!(p.fit.lambda >= 0.0) || !std::isfinite(p.fit.lambda)) throw ValueError("--lambda " + formatValue(p.fit.lambda) + ": must be zero or positive");
    if (p.fit.maxEvaluations < 10) throw ValueError("--max-evaluations " + std::to_string(p.fit.maxEvaluations) + ": must be at least 10");
    if (p.fit.step != 0.0 && !(p.fit.step > 0.0 && std::isfinite(p.fit.step))) throw ValueError("--step " + formatValue(p.fit.step) + ": must be a positive finite length");
    if (p.fit.maxPieces < 1 || p.fit.maxPieces > 64) throw ValueError("--max-pieces " + std::to_string(p.fit.maxPieces) + ": must be between 1 and 64");
    const StrandSet strands = loadStrands("fit", p.input, common, p.strict);

    const auto t0 = std::chrono::steady_clock::now();
    std::vector<std::string> errors;
    const std::vector<StrandFit> fits = fitStrands(strands, p.fit, true, &errors);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

    Scene scene;
    scene.integrator = HelicoidIntegrator::RK4;  // fits are streamlines, regrown exactly
    std::vector<double> relative;
    std::size_t pieces = 0, skipped = 0;
    for (std::size_t i = 0; i < fits.size(); ++i) {
        if (!errors[i].empty()) {
            if (!p.skipDegenerate) throw ValueError(p.input + ": " + errors[i] + " (--skip-degenerate leaves such strands out)");
            ++skipped;
            if (!common.quiet) std::cerr << "vdbhair fit: warning: skipped " << errors[i] << "\n";
            continue;
        }
        const StrandFit& f = fits[i];
        SceneGuide g;
        g.step = f.step;
        g.root = f.root;
        g.frame = f.frame;
        g.pieces = f.pieces;
        g.fit = {{"frechet", f.frechet}, {"coupling", f.coupling}, {"pieces", f.pieces.size()}, {"strand", i}};
        scene.guides.push_back(g);
        relative.push_back(f.frechet / f.length);
        pieces += f.pieces.size();
    }
    if (scene.guides.empty()) throw ValueError(p.input + ": no strand could be fitted");
    writeScene(p.output, scene);

    // Summary: errors relative to strand length, pieces, and how much smaller the fit is.
    std::vector<double> sorted = relative;
    std::sort(sorted.begin(), sorted.end());
    double mean = 0.0;
    for (double r : relative) mean += r;
    mean /= double(relative.size());
    const double p95 = sorted[std::size_t(std::ceil(0.95 * double(sorted.size()))) - 1];
    const std::size_t over = std::size_t(sorted.end() - std::upper_bound(sorted.begin(), sorted.end(), p.fit.maxError));
    if (over && !common.quiet) {
        std::cerr << "vdbhair fit: warning: " << over << " of " << relative.size() << " fits end above --max-error "
                  << formatValue(p.fit.maxError) << " (a last piece takes what remains at --max-pieces or under twice the shortest fragment)\n";
    }
    const double fitBytes = double(scene.guides.size()) * (3 + 6) * 4 + double(pieces) * 6 * 4;  // floats: root, frame, per piece k, length, roll
    const double pointBytes = double(strands.numVertices()) * 12;
    if (common.json) {
        printJson({{"output", p.output}, {"strands", strands.numStrands()}, {"fitted", scene.guides.size()}, {"skipped", skipped}, {"over_max_error", over},
                   {"frechet_relative", {{"mean", mean}, {"p95", p95}}}, {"pieces_per_strand", double(pieces) / double(scene.guides.size())},
                   {"bytes", {{"fit", fitBytes}, {"points", pointBytes}}}, {"compression", pointBytes / fitBytes},
                   {"strands_per_second", double(scene.guides.size()) / seconds}});
    } else if (!common.quiet) {
        std::cout << "fitted " << scene.guides.size() << " of " << strands.numStrands() << " strands with "
                  << double(pieces) / double(scene.guides.size()) << " pieces each on average in " << seconds << " s ("
                  << double(scene.guides.size()) / seconds << " strands/s)\n"
                  << "discrete Frechet distance relative to strand length: mean " << mean << ", 95th percentile " << p95 << "\n"
                  << "size: " << fitBytes << " bytes of helicoid parameters for " << pointBytes << " bytes of points ("
                  << pointBytes / fitBytes << "x smaller)\nwrote " << p.output << " (regrow it with 'vdbhair grow')\n";
    }
    return 0;
}

} // namespace

Command addFitCommand(CLI::App& app, CommonOptions& common)
{
    auto params = std::make_shared<FitCmdParams>();
    CLI::App* sub = app.add_subcommand("fit", "Fit p-helicoids to strands (Frechet measures, Nelder-Mead, piecewise); writes a scene");
    sub->add_option("input", params->input, "Strand file")->required();
    sub->add_option("-o,--output", params->output, "Scene file (.json): one guide per input strand, in input order")->required();
    sub->add_option("--max-error", params->fit.maxError, "Accept a piece within this discrete Frechet distance, as a fraction of the strand length")->capture_default_str();
    sub->add_option("--lambda", params->fit.lambda, "Regularization weight of Eq. 5 (dimensionless: per turn of the piece)")->capture_default_str();
    sub->add_option("--max-pieces", params->fit.maxPieces, "Most pieces per strand")->capture_default_str();
    sub->add_option("--max-evaluations", params->fit.maxEvaluations, "Nelder-Mead evaluations per piece and start")->capture_default_str();
    sub->add_option("--step", params->fit.step, "Tracing step of the fits in world units (default: a quarter of each strand's mean segment length)");
    sub->add_option("--roll", params->fit.optimizeRoll, "Also fit a roll angle of each piece's frame about its tangent (true/false)")->capture_default_str();
    sub->add_flag("--skip-degenerate", params->skipDegenerate, "Leave out strands of zero length instead of failing");
    sub->add_flag("--strict", params->strict, "Reject strands of fewer than 2 vertices instead of dropping them");
    addCommonOptions(sub, common);
    sub->footer("Example: vdbhair fit hair.hair -o fits.json --json && vdbhair grow fits.json -o regrown.hair");
    return {sub, [params, &common] { return runFit(*params, common); }};
}

} // namespace vdbhair::app
