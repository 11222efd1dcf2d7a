// vdbhair retrace IN --field F.vdb -o OUT: every strand restarts at its root and follows the field.
#include "../ParamOptions.h"
#include "../RefineOptions.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/field/FieldJson.h>
#include <vdbhair/field/StreamlineTracer.h>
#include <vdbhair/field/TangentAngles.h>
#include <vdbhair/strands/Measures.h>
#include <vdbhair/helicoid/HelicoidField.h>
#include <vdbhair/io/StrandIO.h>
#include <vdbhair/io/VdbFile.h>

#include <openvdb/openvdb.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <sstream>

namespace vdbhair::app {

namespace {
std::string angleText(double deg, std::size_t counted)
{
    if (!counted) return "none (no vertex inside the field)";
    std::ostringstream os;
    os << deg << " deg";
    return os.str();
}
} // namespace

void printTraceReport(const TraceStats& s, const std::optional<TangentAngles>& angles, double displacement)
{
    std::cout << "retraced " << s.strands << " strands: " << s.fullLength << " full length, " << s.vanished
              << " stopped where the field vanished, " << s.leftField << " left the field, " << s.maxSteps
              << " hit the step limit (" << s.steps << " steps)\n";
    if (angles) {
        std::cout << "mean angle between strand tangents and the field: " << angleText(angles->beforeDeg, angles->countedBefore)
                  << " before, " << angleText(angles->afterDeg, angles->countedAfter) << " after\n";
    }
    std::cout << "mean vertex displacement: " << displacement << "\n";
}

namespace {

/// The command line of retrace: its declared parameters (retraceParameters()) set RetraceParams;
/// the rest say which file and grid the field is read from.
struct RetraceCmdParams
{
    std::string input, output, field, grid = "tangent";
    RetraceParams retrace;
    const CLI::Option* integratorOpt = nullptr;  ///< whether --integrator was given (--helicoid's default differs)
    bool helicoid = false;
};

int runRetrace(const RetraceCmdParams& p, const CommonOptions& common)
{
    checkParamOptions(retraceParameters(), p.retrace);
    TraceParams tp = p.retrace.trace;
    if (p.helicoid && p.integratorOpt->count() == 0) tp.integrator = kHelicoidRetraceIntegrator;
    tp.validate("option");
    strandFormatFromPath(p.output, /*forWriting=*/true);

    if (p.helicoid) {
        const HelicoidFieldGrids field = readHelicoidField(p.field);
        const StrandSet strands = loadStrands("retrace", p.input, common);
        checkStrandLengths("retrace", p.input, strands, common);
        TraceStats stats;
        const StrandSet out = retraceHelicoidField(strands, field, tp, &stats, true, common.interrupter);
        // The angles are measured against the tangent field when the file has one.
        std::optional<TangentAngles> angles;
        if (p.retrace.measure) {
            const std::vector<std::string> names = vdbGridNames(p.field, "retrace(" + p.field + ")");
            if (std::find(names.begin(), names.end(), p.grid) != names.end()) {
                const openvdb::GridBase::Ptr tangent = readVdbGrid(p.field, p.grid, "retrace(" + p.field + ")");
                angles = meanTangentAnglesDeg(strands, out, *tangent);
            }
        }
        const double disp = meanVertexDisplacement(strands, out);
        writeStrands(p.output, out);
        if (common.json) {
            nlohmann::json j = retraceReport(stats, tp, resolveStepLength(tp.step, field.k->voxelSize().x(), "retrace"), disp, angles);
            j["output"] = p.output;
            j["field"] = "helicoid";  // the command's own field (Python retraces through vector grids)
            printJson(j);
        } else if (!common.quiet) {
            printTraceReport(stats, angles, disp);
            std::cout << "wrote " << p.output << " (traced through the helicoid field)\n";
        }
        return 0;
    }
    const openvdb::GridBase::Ptr grid = readVdbGrid(p.field, p.grid, "retrace(" + p.field + ")");
    if (!grid->isType<openvdb::Vec3SGrid>() && !grid->isType<openvdb::Vec3DGrid>()) {
        throw TypeError(p.field + ": grid '" + p.grid + "' holds " + grid->valueType() +
                        " values; retrace needs a vector grid (vec3s or vec3d), such as 'tangent'");
    }
    const StrandSet strands = loadStrands("retrace", p.input, common);
    checkStrandLengths("retrace", p.input, strands, common);

    TraceStats stats;
    const StrandSet out = retraceStrands(strands, *grid, tp, &stats, nullptr, true, common.interrupter);
    std::optional<TangentAngles> angles;
    if (p.retrace.measure) angles = meanTangentAnglesDeg(strands, out, *grid);
    const double disp = meanVertexDisplacement(strands, out);
    writeStrands(p.output, out);
    if (common.json) {
        nlohmann::json j = retraceReport(stats, tp, resolveStep(*grid, tp), disp, angles);
        j["output"] = p.output;
        printJson(j);
    } else if (!common.quiet) {
        printTraceReport(stats, angles, disp);
        std::cout << "wrote " << p.output << "\n";
    }
    return 0;
}

} // namespace

Command addRetraceCommand(CLI::App& app, CommonOptions& common)
{
    auto params = std::make_shared<RetraceCmdParams>();
    CLI::App* sub = addVerb(app, "retrace");
    sub->add_option("input", params->input, "Strand file (roots, lengths and vertex spacing to follow)")->required();
    sub->add_option("--field", params->field, "A .vdb file holding the field")->required();
    sub->add_option("-o,--output", params->output, "Output strand file (.hair .data .obj .ply .vdb .usda)")->required();
    sub->add_option("--grid", params->grid, "Name of the vector grid in the field file")->capture_default_str();
    addParamOptions(sub, params->retrace, retraceParameters());
    CLI::Option* integrator = sub->get_option("--integrator");
    params->integratorOpt = integrator;
    integrator->description(paramHelp(*findParam(retraceParameters(), "integrator")) + "; with --helicoid the default is " +
                                       integratorName(kHelicoidRetraceIntegrator));
    sub->add_flag("--helicoid", params->helicoid, "Trace through the file's helicoid field (vdbhair field --helicoid) instead of the tangent grid");
    addStrictOption(sub, common);
    addCommonOptions(sub, common);
    addReadOptions(sub, common);
    sub->footer("Example: vdbhair retrace hair.hair --field field.vdb -o retraced.hair --measure --json");
    return {sub, [params, &common] { return runRetrace(*params, common); }};
}

} // namespace vdbhair::app
