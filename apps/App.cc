// The command line's heavy half (Command.h): what verbs share that needs the library, and every
// verb registered.
#include "Command.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/field/TangentField.h>
#include <vdbhair/scalp/ScalpSurface.h>
#include <vdbhair/io/StrandIO.h>
#include <vdbhair/io/FileUtil.h>
#include <vdbhair/helicoid/Scene.h>
#include <vdbhair/render/SphereMesh.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <map>

namespace vdbhair::app {

StrandSet loadStrands(const std::string& verb, const std::string& path, const CommonOptions& common, const std::string& vdbGrid)
{
    const Stage stage(common, "reading " + path);
    ReadOptions opts = readOptions(common);
    opts.vdbGrid = vdbGrid;
    ReadReport report;
    StrandSet strands = readStrands(path, opts, &report);
    printWarnings(verb, report, common);
    if (strands.empty()) throw FormatError(path + ": the file has no strands");
    return strands;
}

void checkStrandLengths(const std::string& verb, const std::string& path, const StrandSet& strands,
                        const CommonOptions& common)
{
    const bool strict = common.read.shortStrands == ShortStrandPolicy::Reject;
    std::vector<std::size_t> zero;
    for (std::size_t i = 0; i < strands.numStrands(); ++i) {
        bool moves = false;
        for (std::size_t v = strands.begin(i) + 1; v < strands.end(i) && !moves; ++v) moves = strands.positions[v] != strands.positions[strands.begin(i)];
        if (!moves) zero.push_back(i);
    }
    if (zero.empty()) return;
    std::string which;
    for (std::size_t k = 0; k < zero.size() && k < 5; ++k) which += (k ? ", " : "") + std::to_string(zero[k]);
    if (zero.size() > 5) which += ", ...";
    const std::string what = path + ": " + std::to_string(zero.size()) + " of " + std::to_string(strands.numStrands()) +
                             " strands have zero length (strand" + (zero.size() == 1 ? " " : "s ") + which +
                             ": every vertex at one point), so they have no direction";
    if (zero.size() == strands.numStrands()) throw FormatError(what + "; with no strand of non-zero length there is nothing to " + verb);
    const std::string flag = readParamName("strict").flag;
    if (strict) throw FormatError(what + "; " + flag + " rejects them");
    ReadReport report;
    report.warnings.push_back(what + "; they are ignored (" + flag + " rejects them)");
    printWarnings(verb, report, common);
}

StrandSet loadStrandsOrScene(const std::string& verb, const std::string& path, const CommonOptions& common,
                             const std::string& vdbGrid, TriangleMesh* head)
{
    if (fileExtension(path) == ".json") {
        const Scene scene = readScene(path);
        if (head && scene.head) *head = makeSphereMesh(scene.head->center, scene.head->radius);
        StrandSet s = growScene(scene, {}, true, common.interrupter);
        if (s.empty()) throw FormatError(path + ": the scene has no guides");
        return s;
    }
    return loadStrands(verb, path, common, vdbGrid);
}

void addScalpOptions(CLI::App* sub, ScalpOptions& opts)
{
    sub->add_option("--scalp", opts.scalp, "The scalp for --space scalp: a sphere CX,CY,CZ,R in world units, or a .vdb with a level set "
                    "'surface' (vdbhair scalp) or a head mesh (.ply, .obj), measured along rays from the sphere fitted to the roots "
                    "(default: that sphere)");
}

std::vector<double> ScalpOptions::sphere() const
{
    // Four comma-separated numbers are a sphere; anything else names a file.
    if (scalp.empty() || scalp.find(',') == std::string::npos || std::filesystem::exists(scalp)) return {};
    std::vector<double> v;
    std::size_t start = 0;
    while (true) {
        const std::size_t comma = scalp.find(',', start);
        const std::string item = scalp.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
        char* end = nullptr;
        const double x = std::strtod(item.c_str(), &end);
        if (item.empty() || *end || !std::isfinite(x))
            throw ValueError("--scalp '" + scalp + "': '" + item + "' is not a number (a sphere is CX,CY,CZ,R; a scalp file must exist)");
        v.push_back(x);
        if (comma == std::string::npos) break;
        start = comma + 1;
    }
    if (v.size() != 4 || !(v[3] > 0.0)) throw ValueError("--scalp '" + scalp + "': a sphere is CX,CY,CZ,R with R > 0");
    return v;
}

openvdb::FloatGrid::Ptr applyScalpOptions(const ScalpOptions& opts, const StrandSet& strands, FieldParams& params,
                                          const CommonOptions& common)
{
    const Vec3d up = params.scalp.up;
    const std::vector<double> sphere = opts.sphere();
    if (params.space != FieldSpace::Scalp) {
        if (!opts.scalp.empty()) throw ValueError("--scalp " + opts.scalp + ": needs --space scalp");
        return nullptr;
    }
    std::vector<Vec3f> roots;
    for (std::size_t i = 0; i < strands.numStrands(); ++i) roots.push_back(strands.root(i));
    ScalpSphere given;
    if (!sphere.empty()) {
        given.center = Vec3d(sphere[0], sphere[1], sphere[2]);
        given.radius = sphere[3];
    }
    const openvdb::FloatGrid::Ptr surface = sphere.empty() ? readScalpOption(opts.scalp, common) : nullptr;
    try {
        useScalpSpace(params, roots, up, sphere.empty() ? nullptr : &given, surface);
    } catch (const ValueError& e) {
        throw ValueError((opts.scalp.empty() ? std::string("--space scalp") : "--scalp " + opts.scalp) + ": " + spelledMessage(e, ParamSpelling::Flag));
    }
    return surface;
}

openvdb::FloatGrid::Ptr readScalpOption(const std::string& path, const CommonOptions& common)
{
    if (path.empty()) return nullptr;
    const Stage stage(common, "reading " + path);
    return readScalp(path, common.interrupter);
}

std::vector<Command> addCommands(CLI::App& app, CommonOptions& common)
{
    using Adder = Command (*)(CLI::App&, CommonOptions&);
    static const std::map<std::string, Adder> adders = {
        {"info", addInfoCommand}, {"convert", addConvertCommand}, {"field", addFieldCommand},
        {"retrace", addRetraceCommand}, {"refine", addRefineCommand}, {"grow", addGrowCommand},
        {"fit", addFitCommand}, {"scalp", addScalpCommand}, {"roots", addRootsCommand},
        {"interpolate", addInterpolateCommand}, {"reconstruct", addReconstructCommand}, {"synth", addSynthCommand},
        {"transfer", addTransferCommand}, {"comb", addCombCommand}, {"inspect", addInspectCommand}, {"compare", addCompareCommand},
        {"render", addRenderCommand}, {"demo", addDemoCommand}, {"batch", addBatchCommand},
        {"prepare", addPrepareCommand}};
    std::vector<Command> commands;
    for (const Verb& v : verbs()) commands.push_back(adders.at(v.name)(app, common));
    return commands;
}

} // namespace vdbhair::app
