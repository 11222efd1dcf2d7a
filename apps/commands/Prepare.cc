// vdbhair prepare IN OUT: a hairstyle made ready for a dataset (vdbhair/dataset/Prepare.h): even
// roots kept (--strands), moved onto a common head (--head, --align-to), resampled (--points),
// pushed out of the head (--fix-penetration).
#include "../Command.h"
#include "../ParamOptions.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/dataset/Prepare.h>
#include <vdbhair/field/HeadObstacle.h>
#include <vdbhair/io/MeshFile.h>
#include <vdbhair/io/StrandIO.h>
#include <vdbhair/scalp/HeadFile.h>

#include <cstdio>

namespace vdbhair::app {

namespace {

struct PrepareCmdParams
{
    std::vector<std::string> files;  ///< IN OUT, or IN with -o OUT
    std::string output, head, alignTo, fixPenetration;
    PrepareParams prepare;  ///< its declared parameters (prepareParameters()) are options
};

std::string fmt(double v)
{
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.6g", v);
    return buf;
}

void printReport(const std::string& input, const std::string& output, const PrepareReport& r)
{
    std::cout << input << " -> " << output << ": " << r.strands << " strands, " << r.vertices << " vertices (from "
              << r.inputStrands << " strands, " << r.inputVertices << " vertices)\n";
    if (r.subsample) {
        std::cout << "  even roots: " << r.strands << " of " << r.inputStrands << " kept, smallest root spacing "
                  << fmt(r.subsample->minSpacing) << ", every root within " << fmt(r.subsample->coverageRadius) << " of a kept one\n";
    }
    if (r.align) {
        const Similarity& t = r.align->transform;
        std::cout << "  aligned (" << alignMethodName(r.align->method) << "): scale " << fmt(t.scale) << ", translation ("
                  << fmt(t.translation.x()) << ", " << fmt(t.translation.y()) << ", " << fmt(t.translation.z()) << "), rotation rows";
        for (int i = 0; i < 3; ++i) std::cout << " (" << fmt(t.rotation(i, 0)) << ", " << fmt(t.rotation(i, 1)) << ", " << fmt(t.rotation(i, 2)) << ")";
        std::cout << "\n  residual: RMS " << fmt(r.align->rms) << ", max " << fmt(r.align->max) << " (nearest share), RMS "
                  << fmt(r.align->rmsAll) << " over all " << r.align->pairs << " head vertices used\n";
    }
    if (r.points) std::cout << "  resampled to " << r.points << " points per strand\n";
    if (r.fixed) {
        std::cout << "  penetration (" << r.fixHead << "): " << r.enteringBefore << " strands entered the head before, "
                  << r.enteringAfter << " after; " << r.collision.strandsMoved << " strands moved";
        if (r.rootsLifted) std::cout << ", " << r.rootsLifted << " lifted to the surface by their root";
        if (r.collision.verticesTooDeep) std::cout << ", " << r.collision.verticesTooDeep << " vertices still too deep";
        std::cout << "\n";
    }
}

int runPrepare(PrepareCmdParams p, const CommonOptions& common)
{
    // The command line, before anything is read.
    std::vector<std::string> inputs = p.files;
    if (p.output.empty()) {
        if (inputs.size() < 2) throw ValueError("needs an input and an output: 'prepare IN OUT' or 'prepare IN -o OUT'");
        p.output = inputs.back();
        inputs.pop_back();
    }
    if (inputs.size() != 1) throw ValueError("takes one input (got " + std::to_string(inputs.size()) + "); run it through 'vdbhair batch' for a folder");
    const std::string& input = inputs[0];
    strandFormatFromPath(input);
    strandFormatFromPath(p.output, /*forWriting=*/true);
    checkParamOptions(prepareParameters(), p.prepare);
    p.prepare.validate();
    if (!p.alignTo.empty() && p.head.empty()) {
        throw ValueError("--align-to " + p.alignTo + " needs --head, the groom's own head mesh: that head is fitted to " + p.alignTo +
                         " and the strands move with it");
    }

    StrandSet strands = loadStrands("prepare", input, common);
    if (strands.empty()) throw FormatError(input + ": the file has no strands; nothing to write to " + p.output);
    TriangleMesh head, target;
    if (!p.head.empty()) {
        const Stage stage(common, "reading " + p.head);
        head = readTriangleMesh(p.head);
    }
    if (!p.alignTo.empty()) {
        const Stage stage(common, "reading " + p.alignTo);
        target = readTriangleMesh(p.alignTo);
    }
    HeadObstacle fixHead;
    if (!p.fixPenetration.empty()) {
        const Stage stage(common, "reading " + p.fixPenetration);
        fixHead = readHeadObstacle(p.fixPenetration, "--fix-penetration " + p.fixPenetration, HeadPolicy::KeepOutside);
    }
    PrepareReport report;
    {
        const Stage stage(common, "preparing");
        report = prepareStrands(strands, p.prepare, p.head.empty() ? nullptr : &head, p.alignTo.empty() ? nullptr : &target,
                                p.fixPenetration.empty() ? nullptr : &fixHead);
    }
    {
        const Stage stage(common, "writing " + p.output);
        writeStrands(p.output, strands);
    }
    if (common.json) {
        nlohmann::json j = toJson(report);
        j["input"] = input;
        j["output"] = p.output;
        j["head"] = p.head.empty() ? nlohmann::json(nullptr) : nlohmann::json(p.head);
        j["align_to"] = p.alignTo.empty() ? nlohmann::json(nullptr) : nlohmann::json(p.alignTo);
        printJson(j);
    } else if (!common.quiet) {
        printReport(input, p.output, report);
    }
    return 0;
}

} // namespace

Command addPrepareCommand(CLI::App& app, CommonOptions& common)
{
    auto params = std::make_shared<PrepareCmdParams>();
    CLI::App* sub = addVerb(app, "prepare");
    sub->add_option("files", params->files, "IN OUT, or IN with -o OUT")->required();
    sub->add_option("-o,--output", params->output, "Output strand file; its extension picks the format (.hair .data .obj .ply .vdb .usda .abc)");
    addParamOptions(sub, params->prepare, prepareParameters());
    sub->add_option("--head", params->head, "The groom's own head mesh (.ply, .obj), in the strands' frame: the source of --align-to");
    sub->add_option("--align-to", params->alignTo,
                    "A common head mesh (.ply, .obj): --head is fitted onto it by a similarity (scale, rotation, translation) and the "
                    "strands move with it; the transform and the residual are reported");
    sub->add_option("--fix-penetration", params->fixPenetration,
                    "A head (mesh or .vdb level set) in the output's frame, e.g. the --align-to mesh: strands that enter it are bent out "
                    "(lengths kept, roots fixed; a root inside the scalp may stay as deep as it is)");
    addStrictOption(sub, common);
    addCommonOptions(sub, common);
    addReadOptions(sub, common);
    sub->footer("Order: --strands, --align-to, --points, --fix-penetration.\n"
                "Example: vdbhair prepare straight.hair out.data --head woman_head.ply --align-to head_model.ply "
                "--points 100 --strands 1000 --fix-penetration head_model.ply");
    return {sub, [params, &common] { return runPrepare(*params, common); }};
}

} // namespace vdbhair::app
