// vdbhair reconstruct IN -o OUT --guides 10%: a hairstyle rebuilt from a share of its strands
// (Piuze et al. 2011, §5.4), measured against the original both ways (helicoids and points).
#include "../Command.h"
#include "../ParamOptions.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/Format.h>
#include <vdbhair/helicoid/HelicoidJson.h>
#include <vdbhair/helicoid/Reconstruction.h>
#include <vdbhair/io/FileUtil.h>
#include <vdbhair/io/StrandIO.h>
#include <vdbhair/scalp/HeadFile.h>

#include <cmath>
#include <cstdio>
#include <sstream>

namespace vdbhair::app {

namespace {

struct ReconstructCmdParams
{
    std::string input, output, method = "points", errors, head;
    /// The share of guides as a percentage ("10%"), into rec.guideFraction.
    std::string guides = formatNumber(100.0 * ReconstructParams{}.guideFraction) + "%";
    ReconstructParams rec;  ///< its declared parameters (reconstructParameters()) but the share are options
};

/// "10%", "10 %" or "10": a percentage of the strands, as a fraction.
double parsePercent(const std::string& text)
{
    std::string s = text;
    while (!s.empty() && (s.back() == '%' || s.back() == ' ')) s.pop_back();
    char* end = nullptr;
    const double v = std::strtod(s.c_str(), &end);
    if (s.empty() || *end != '\0' || !std::isfinite(v)) throw ValueError("--guides '" + text + "': expected a percentage such as 10%");
    if (!(v > 0.0 && v <= 100.0)) throw ValueError("--guides " + text + ": must be more than 0 % and at most 100 % of the strands");
    return v / 100.0;
}

int runReconstruct(ReconstructCmdParams p, const CommonOptions& common)
{
    if (p.method != "helicoid" && p.method != "points") throw ValueError("--method '" + p.method + "' is not one of helicoid, points");
    p.rec.guideFraction = parsePercent(p.guides);
    strandFormatFromPath(p.output, /*forWriting=*/true);
    checkParamOptions(reconstructParameters(), p.rec);
    const StrandSet strands = loadStrands("reconstruct", p.input, common);
    HeadObstacle head;
    if (!p.head.empty() && p.head != "none") head = readHeadObstacle(p.head, "--head " + p.head);
    const ReconstructResult r = reconstructHairstyle(strands, p.rec, true, common.interrupter, head.unset() || head.empty() ? nullptr : &head);
    {
        const Stage stage(common, "writing " + p.output);
        writeStrands(p.output, p.method == "points" ? r.points : r.helicoid);
        if (!p.errors.empty()) {
            std::ostringstream csv;
            csv << "strand,guide,helicoid,points,nearest\n";
            std::vector<char> isGuide(strands.numStrands(), 0);
            for (std::size_t g : r.guides) isGuide[g] = 1;
            char line[128];
            for (std::size_t i = 0; i < strands.numStrands(); ++i) {
                std::snprintf(line, sizeof line, "%zu,%d,%.9g,%.9g,%.9g\n", i, int(isGuide[i]), r.helicoidErrors.relative[i], r.pointErrors.relative[i],
                              r.nearestErrors.relative[i]);
                csv << line;
            }
            writeFileAtomic(p.errors, csv.str(), "reconstruct(" + p.errors + ")");
        }
    }
    const std::size_t S = strands.numStrands();
    if (common.json) {
        nlohmann::json j = reconstructReport(r, p.rec);
        j["output"] = p.output;
        j["method"] = p.method;  // the reconstruction written
        printJson(j);
    } else if (!common.quiet) {
        char buf[256];
        std::snprintf(buf, sizeof buf, " guides (%.3g %%, %s); fits: mean %.3g %%, %.2f pieces, %.3f s\n", 100.0 * double(r.guides.size()) / double(S),
                      guideSelectionName(p.rec.selection), 100.0 * r.fitSummary.meanRelative, r.fitSummary.piecesPerStrand, r.fitSeconds);
        std::cout << "reconstructed " << S << " strands from " << r.guides.size() << buf << "discrete Frechet distance / strand length:\n";
        std::snprintf(buf, sizeof buf, "%-17s %10s %10s %14s %14s %9s\n", "method", "mean", "p95", "mean interp.", "p95 interp.", "time s");
        std::cout << buf;
        for (int m = 0; m < 3; ++m) {
            const ReconstructErrors& e = m == 0 ? r.helicoidErrors : m == 1 ? r.pointErrors : r.nearestErrors;
            const std::string name = m == 0 ? "helicoid (" + std::string(helicoidBlendName(p.rec.helicoid.blend)) + ")" : m == 1 ? "points (" + std::string(guideGroupingName(p.rec.points.grouping)) + ")" : "nearest guide";
            std::snprintf(buf, sizeof buf, "%-17s %9.3f%% %9.3f%% %13.3f%% %13.3f%% %9.3f\n", name.c_str(), 100.0 * e.mean, 100.0 * e.p95,
                          100.0 * e.meanInterpolated, 100.0 * e.p95Interpolated, e.seconds);
            std::cout << buf;
        }
        std::cout << "as papers measure (all strands): Perm's root-aligned position error / curvature error"
                  << (r.pointErrors.oriented.empty() ? "" : "; HairGS F1 at 2 mm/20, 3 mm/30, 4 mm/40, 4 mm/90 degrees") << ":\n";
        for (int m = 0; m < 3; ++m) {
            const ReconstructErrors& e = m == 0 ? r.helicoidErrors : m == 1 ? r.pointErrors : r.nearestErrors;
            std::snprintf(buf, sizeof buf, "%-17s %10.4g %10.4g", m == 0 ? "helicoid" : m == 1 ? "points" : "nearest guide", e.permPosition, e.permCurvature);
            std::cout << buf;
            for (const OrientedMatch& o : e.oriented) {
                std::snprintf(buf, sizeof buf, " %6.3f", o.f1);
                std::cout << buf;
            }
            std::cout << "\n";
        }
        std::snprintf(buf, sizeof buf, "%.1f %% of the original strands, helicoid %.1f %%, points %.1f %%, nearest guide %.1f %%", 100.0 * r.originalLeavingVolume,
                      100.0 * r.helicoidErrors.leavingVolume, 100.0 * r.pointErrors.leavingVolume, 100.0 * r.nearestErrors.leavingVolume);
        std::cout << "leaving the guides' hair volume (voxel " << formatValue(r.volumeVoxel) << ", interpolated strands): " << buf << "\n";
        if (r.headMeasured) {
            std::snprintf(buf, sizeof buf, "%.1f %% of the original strands, helicoid %.1f %%, points %.1f %%, nearest guide %.1f %%", 100.0 * r.originalEnteringHead,
                          100.0 * r.helicoidErrors.enteringHead, 100.0 * r.pointErrors.enteringHead, 100.0 * r.nearestErrors.enteringHead);
            std::cout << "passing into the head (" << head.describe(false) << "): " << buf << "\n";
        }
        std::cout << "wrote " << p.output << " (" << p.method << ")" << (p.errors.empty() ? "" : " and " + p.errors) << "\n";
    }
    return 0;
}

} // namespace

Command addReconstructCommand(CLI::App& app, CommonOptions& common)
{
    auto params = std::make_shared<ReconstructCmdParams>();
    CLI::App* sub = addVerb(app, "reconstruct");
    sub->add_option("input", params->input, "Strand file")->required();
    sub->add_option("-o,--output", params->output, "The reconstructed strands (any strand format), by --method")->required();
    sub->add_option("--guides", params->guides, "Share of the strands used as guides, in (0, 100] %")->capture_default_str();
    sub->add_option("--method", params->method, "Which reconstruction to write: points (the guides' points, by likeness) or helicoid (all three are measured)")->capture_default_str();
    addParamOptions(sub, params->rec, reconstructParameters(), {"guides"});
    sub->add_option("--head", params->head, "A head (mesh or .vdb level set) to measure the shares of strands passing into it against (nothing is moved)");
    sub->add_option("--errors", params->errors, "Also write every strand's relative error, every way, as CSV");
    addCommonOptions(sub, common);
    addReadOptions(sub, common);
    sub->footer("Example: vdbhair reconstruct straight.hair -o rebuilt.hair --guides 10% --json");
    return {sub, [params, &common] { return runReconstruct(*params, common); }};
}

} // namespace vdbhair::app
