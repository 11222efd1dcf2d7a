// vdbhair compare A B: the measures hair papers report, of a candidate hairstyle B against a
// reference A (vdbhair/compare/HairComparison.h).
#include "../Command.h"
#include "../ParamOptions.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/compare/HairComparison.h>
#include <vdbhair/field/HeadObstacle.h>
#include <vdbhair/io/FileUtil.h>
#include <vdbhair/scalp/HeadFile.h>

#include <cmath>
#include <cstdio>
#include <sstream>

namespace vdbhair::app {

namespace {

struct CompareCmdParams
{
    std::string a, b, head, perStrand;
    CompareParams params;  ///< its declared parameters (compareParameters()) are options
};

int runCompare(CompareCmdParams p, const CommonOptions& common)
{
    checkParamOptions(compareParameters(), p.params);
    p.params.validate();
    if (!p.perStrand.empty() && fileExtension(p.perStrand) != ".csv") {
        throw ValueError("--per-strand " + p.perStrand + ": must name a .csv file");
    }
    const StrandSet a = loadStrands("compare", p.a, common);
    const StrandSet b = loadStrands("compare", p.b, common);
    HeadObstacle head;
    if (!p.head.empty()) head = readHeadObstacle(p.head, "--head " + p.head);
    HairComparison c;
    {
        const Stage stage(common, "comparing");
        c = compareHairstyles(a, b, p.params, head.unset() || head.empty() ? nullptr : &head, true);
    }
    if (!p.perStrand.empty()) {
        const Stage stage(common, "writing " + p.perStrand);
        std::ostringstream csv;
        csv << "strand,chamfer" << (c.paired ? ",position,curvature,frechet" : "") << "\n";
        char line[160];
        for (std::size_t i = 0; i < c.strandsA; ++i) {
            if (c.paired) {
                std::snprintf(line, sizeof line, "%zu,%.9g,%.9g,%.9g,%.9g\n", i, c.chamfer.perStrandA[i], c.perm.position[i], c.perm.curvature[i], c.frechet[i]);
            } else {
                std::snprintf(line, sizeof line, "%zu,%.9g\n", i, c.chamfer.perStrandA[i]);
            }
            csv << line;
        }
        writeFileAtomic(p.perStrand, csv.str(), "compare(" + p.perStrand + ")");
    }
    if (common.json) {
        nlohmann::json j = toJson(c);
        j["a"] = p.a;
        j["b"] = p.b;
        if (!p.perStrand.empty()) j["per_strand"] = p.perStrand;
        printJson(j);
        return 0;
    }
    std::printf("A (reference): %s, %zu strands, %zu vertices\n", p.a.c_str(), c.strandsA, c.verticesA);
    std::printf("B (candidate): %s, %zu strands, %zu vertices\n", p.b.c_str(), c.strandsB, c.verticesB);
    if (c.oriented.empty()) {
        std::printf("oriented points: not measured (give --unit for HairGS's 2-4 mm thresholds, or --threshold D:ANGLE in file units)\n");
    } else {
        std::printf("oriented points (HairGS)   precision  recall     F1   consistency\n");
        for (const OrientedMatch& m : c.oriented) {
            char at[64];
            if (c.metersPerUnit > 0.0) std::snprintf(at, sizeof at, "%g mm / %g deg", m.threshold.distance * c.metersPerUnit * 1000.0, m.threshold.angleDegrees);
            else std::snprintf(at, sizeof at, "%g / %g deg", m.threshold.distance, m.threshold.angleDegrees);
            std::printf("  %-24s %9.4f %7.4f %7.4f %9.4f\n", at, m.precision, m.recall, m.f1, m.strandConsistency);
        }
    }
    std::printf("Chamfer distance:          %g (A to B %g, B to A %g)\n", c.chamfer.mean, c.chamfer.aToB, c.chamfer.bToA);
    if (c.paired) {
        std::printf("strand pairs (%zu points):  position error %g, curvature error %g (Perm, root-aligned)\n", p.params.samples, c.perm.meanPosition,
                    c.perm.meanCurvature);
        std::printf("discrete Frechet / length: mean %g, 95th percentile %g, max %g\n", c.frechetMean, c.frechetP95, c.frechetMax);
    } else {
        if (c.strandsA == c.strandsB) std::printf("strand pairs: not measured (--unpaired)\n");
        else std::printf("strand pairs: not measured (%zu strands against %zu: the counts differ)\n", c.strandsA, c.strandsB);
    }
    std::printf("B leaving A's hair volume: %.2f %% of its strands (voxel %g)\n", 100.0 * c.leavingVolume, c.volumeVoxel);
    if (c.headMeasured) std::printf("passing into the head:     A %.2f %%, B %.2f %% of the strands\n", 100.0 * c.enteringHeadA, 100.0 * c.enteringHeadB);
    if (!p.perStrand.empty()) std::printf("wrote %s\n", p.perStrand.c_str());
    return 0;
}

} // namespace

Command addCompareCommand(CLI::App& app, CommonOptions& common)
{
    auto params = std::make_shared<CompareCmdParams>();
    CLI::App* sub = addVerb(app, "compare");
    sub->add_option("a", params->a, "The reference hairstyle (any strand format)")->required();
    sub->add_option("b", params->b, "The hairstyle compared with it (precision is the share of its oriented points matched in A)")->required();
    addParamOptions(sub, params->params, compareParameters());
    sub->add_option("--head", params->head, "A head (mesh or .vdb level set): the shares of A's and B's strands passing into it");
    sub->add_option("--per-strand", params->perStrand, "Write each strand of A's values as CSV: chamfer, and with equal strand counts position, curvature, frechet");
    addCommonOptions(sub, common);
    addReadOptions(sub, common);
    sub->footer("Example: vdbhair compare straight.hair rebuilt.hair --unit cm --json");
    return {sub, [params, &common] { return runCompare(*params, common); }};
}

} // namespace vdbhair::app
