#include "Command.h"
#include "TerminalProgress.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/Version.h>
#include <vdbhair/field/TangentField.h>
#include <vdbhair/scalp/ScalpSurface.h>
#include <vdbhair/io/StrandIO.h>
#include <vdbhair/io/FileUtil.h>
#include <vdbhair/helicoid/Scene.h>
#include <vdbhair/render/SphereMesh.h>

#include <openvdb/Exceptions.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <filesystem>
#include <atomic>
#include <new>
#include <cctype>
#include <limits>
#include <memory>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>

namespace vdbhair::app {

void addCommonOptions(CLI::App* sub, CommonOptions& common, bool withJson)
{
    // Checked in run() (one clear message instead of CLI11's range with a 309-digit bound).
    sub->add_option("--threads", common.threads, "Worker threads (0: all cores); results do not depend on it");
    sub->add_flag("--no-clobber", common.noClobber, "Refuse to replace an existing output file (the default replaces it atomically)");
    if (withJson) sub->add_flag("--json", common.json, "Print one JSON object on stdout instead of prose");
    sub->add_flag("--quiet,-q", common.quiet, "No progress and no warnings on stderr");
}

void printWarnings(const std::string& verb, const ReadReport& report, const CommonOptions& common)
{
    if (common.quiet) return;
    // Readers name library parameters; a verb that reads strands may render them (`render --up`).
    static const FlagNames readerFlags = {{"RenderParams::up", "--up"}};
    for (const std::string& w : report.warnings) std::cerr << "vdbhair " << verb << ": warning: " << withFlagNames(w, readerFlags) << "\n";
}

std::string formatValue(double v)
{
    char buf[32];
    for (int precision = 1; precision <= 17; ++precision) {
        std::snprintf(buf, sizeof buf, "%.*g", precision, v);
        if (std::strtod(buf, nullptr) == v || !std::isfinite(v)) break;
    }
    return buf;
}

void warnBandWithoutZero(const std::string& verb, const std::string& input, double area, double areaWithoutZero,
                         const CommonOptions& common)
{
    if (!(areaWithoutZero > 0.01 * (area + areaWithoutZero)) || common.quiet) return;
    std::cerr << "vdbhair " << verb << ": warning: " << input << ": " << formatValue(std::round(1000.0 * areaWithoutZero / (area + areaWithoutZero)) / 10.0)
              << " % of the surface's band never crosses zero (an open or inside-out part of the mesh that has no inside); no roots there\n";
}

void printJson(const nlohmann::json& j)
{
    // A file name need not be UTF-8: invalid bytes print as U+FFFD instead of ending the run.
    std::cout << j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace) << std::endl;
}

StrandSet loadStrands(const std::string& verb, const std::string& path, const CommonOptions& common, bool strict,
                      const std::string& vdbGrid)
{
    const Stage stage(common, "reading " + path);
    ReadOptions opts;
    opts.vdbGrid = vdbGrid;
    opts.interrupter = common.interrupter;
    if (strict) opts.shortStrands = ShortStrandPolicy::Reject;
    ReadReport report;
    StrandSet strands = readStrands(path, opts, &report);
    printWarnings(verb, report, common);
    if (strands.empty()) throw FormatError(path + ": the file has no strands");
    return strands;
}

void checkStrandLengths(const std::string& verb, const std::string& path, const StrandSet& strands,
                        const CommonOptions& common, bool strict)
{
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
    if (strict) throw FormatError(what + "; --strict rejects them");
    ReadReport report;
    report.warnings.push_back(what + "; they are ignored (--strict rejects them)");
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
    return loadStrands(verb, path, common, false, vdbGrid);
}

void addScalpOptions(CLI::App* sub, ScalpOptions& opts)
{
    sub->add_option("--space", opts.space, "Grid space: world (default; any hairstyle) or scalp (Wang et al.'s (u,v,w); hair over the scalp)")
        ->capture_default_str();
    sub->add_option("--scalp", opts.scalp, "The scalp for --space scalp: a sphere CX,CY,CZ,R in world units, or a .vdb with a level set "
                    "'surface' (vdbhair scalp) or a head mesh (.ply, .obj), measured along rays from the sphere fitted to the roots "
                    "(default: that sphere)");
    sub->add_option("--up", opts.up, "The scalp's up axis for --space scalp: x, y, z, -x, -y or -z")->capture_default_str();
}

Vec3d axisFromName(const std::string& name, const std::string& option)
{
    const std::string axis = name.size() == 2 && name[0] == '-' ? name.substr(1) : name;
    const double sign = name.size() == 2 && name[0] == '-' ? -1.0 : 1.0;
    if (axis == "x") return Vec3d(sign, 0.0, 0.0);
    if (axis == "y") return Vec3d(0.0, sign, 0.0);
    if (axis == "z") return Vec3d(0.0, 0.0, sign);
    throw ValueError(option + " '" + name + "' is not one of x, y, z, -x, -y, -z");
}

std::string axisName(const Vec3d& axis)
{
    for (const char* name : {"x", "y", "z", "-x", "-y", "-z"}) {
        if (axisFromName(name, "axis") == axis) return name;
    }
    throw ValueError("axis (" + formatValue(axis.x()) + ", " + formatValue(axis.y()) + ", " + formatValue(axis.z()) +
                     ") is not one of x, y, z, -x, -y, -z");
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
    params.space = fieldSpaceFromName(opts.space);
    const Vec3d up = axisFromName(opts.up, "--up");
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
        throw ValueError((opts.scalp.empty() ? std::string("--space scalp") : "--scalp " + opts.scalp) + ": " + e.what());
    }
    return surface;
}

openvdb::FloatGrid::Ptr readScalpOption(const std::string& path, const CommonOptions& common)
{
    if (path.empty()) return nullptr;
    const Stage stage(common, "reading " + path);
    return readScalp(path, common.interrupter);
}

namespace {

/// Levenshtein distance between @a a and @a b (short words: the plain dynamic programme).
std::size_t editDistance(const std::string& a, const std::string& b)
{
    std::vector<std::size_t> row(b.size() + 1);
    for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
    for (std::size_t i = 1; i <= a.size(); ++i) {
        std::size_t diag = row[0];
        row[0] = i;
        for (std::size_t j = 1; j <= b.size(); ++j) {
            const std::size_t up = row[j];
            row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (a[i - 1] == b[j - 1] ? 0 : 1)});
            diag = up;
        }
    }
    return row[b.size()];
}

} // namespace

std::vector<std::string> nearestVerbs(const std::string& word, const std::vector<std::string>& verbs)
{
    // A verb the word starts or a verb that starts with the word counts as distance 1.
    std::size_t best = std::numeric_limits<std::size_t>::max();
    std::vector<std::pair<std::size_t, std::string>> scored;
    for (const std::string& v : verbs) {
        std::size_t d = editDistance(word, v);
        if (!word.empty() && (v.rfind(word, 0) == 0 || word.rfind(v, 0) == 0)) d = std::min<std::size_t>(d, 1);
        scored.push_back({d, v});
        best = std::min(best, d);
    }
    std::vector<std::string> out;
    const std::size_t limit = std::max<std::size_t>(2, word.size() / 3);
    if (best > limit) return out;
    for (const auto& [d, v] : scored) if (d == best) out.push_back(v);
    return out;
}

namespace {

/// Memory kept for unwinding after an allocation fails. OpenVDB's Tree::clear() allocates while a
/// grid is destroyed, so when a failed allocation left nothing, the unwinding itself ran out and
/// ended in std::terminate (measured: `field` under `ulimit -v 250000` aborted with SIGABRT and
/// "terminate called after throwing an instance of 'std::bad_alloc'"). The first allocation that
/// fails frees this reserve and throws, so the grids are destroyed with its room and the verb ends
/// with its one-line "out of memory". The block is never touched: it holds address space, not RAM.
constexpr std::size_t kUnwindReserveBytes = std::size_t(64) << 20;
std::atomic<void*> sUnwindReserve{nullptr};

void releaseUnwindReserve()
{
    std::free(sUnwindReserve.exchange(nullptr));
    throw std::bad_alloc();
}

void keepUnwindReserve()
{
    if (sUnwindReserve.load() == nullptr) sUnwindReserve.store(std::malloc(kUnwindReserveBytes));
    std::set_new_handler(releaseUnwindReserve);
}

} // namespace

std::vector<Command> addCommands(CLI::App& app, CommonOptions& common)
{
    std::vector<Command> commands;
    commands.push_back(addInfoCommand(app, common));
    commands.push_back(addConvertCommand(app, common));
    commands.push_back(addFieldCommand(app, common));
    commands.push_back(addRetraceCommand(app, common));
    commands.push_back(addRefineCommand(app, common));
    commands.push_back(addGrowCommand(app, common));
    commands.push_back(addFitCommand(app, common));
    commands.push_back(addScalpCommand(app, common));
    commands.push_back(addRootsCommand(app, common));
    commands.push_back(addInterpolateCommand(app, common));
    commands.push_back(addReconstructCommand(app, common));
    commands.push_back(addSynthCommand(app, common));
    commands.push_back(addTransferCommand(app, common));
    commands.push_back(addCombCommand(app, common));
    commands.push_back(addInspectCommand(app, common));
    commands.push_back(addRenderCommand(app, common));
    commands.push_back(addDemoCommand(app, common));
    commands.push_back(addBatchCommand(app, common));
    return commands;
}

std::string withFlagNames(const std::string& message, const FlagNames& names)
{
    auto wordChar = [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-'; };
    std::string out = message;
    for (const auto& [name, flag] : names) {
        const bool identifier = std::any_of(name.begin(), name.end(), [](char c) { return std::isupper(static_cast<unsigned char>(c)); });
        for (std::size_t at = out.find(name); at != std::string::npos; at = out.find(name, at)) {
            const std::size_t end = at + name.size();
            const bool word = (at == 0 || !wordChar(out[at - 1])) && (end == out.size() || !wordChar(out[end]));
            const bool named = at == 0 || (at >= 2 && out.compare(at - 2, 2, ": ") == 0);
            if (word && (identifier || named)) {
                out.replace(at, name.size(), flag);
                at += flag.size();
            } else {
                at = end;
            }
        }
    }
    return out;
}

int run(int argc, char** argv)
{
    CLI::App app{"vdbhair " VDBHAIR_VERSION_STRING
                 ": hair geometry on OpenVDB - strands, tangent fields and generalized helicoids.\n"
                 "Formats: .hair .data .obj .ply .vdb .usda (read and write), .tfx .bin .convdata (read).",
                 "vdbhair"};
    app.set_version_flag("--version", "vdbhair " VDBHAIR_VERSION_STRING);
    app.require_subcommand(1, 1);
    app.footer("Run 'vdbhair <verb> --help' for a verb's options. Errors go to stderr as\n"
               "'vdbhair <verb>: <what, the value, the rule>' with a non-zero exit status.");
    CommonOptions common;
    const std::vector<Command> commands = addCommands(app, common);

    std::vector<std::string> verbs;
    for (const Command& c : commands) verbs.push_back(c.sub->get_name());

    // `vdbhair help [VERB]` is `vdbhair [VERB] --help`.
    std::vector<std::string> args(argv, argv + argc);
    if (args.size() >= 2 && args[1] == "help") {
        args.erase(args.begin() + 1);
        args.push_back("--help");
    }
    // An unknown verb: say so and suggest the nearest (`vdbhair inf` -> did you mean info?).
    if (args.size() >= 2 && !args[1].empty() && args[1][0] != '-' &&
        std::find(verbs.begin(), verbs.end(), args[1]) == verbs.end()) {
        const std::vector<std::string> near = nearestVerbs(args[1], verbs);
        std::cerr << "vdbhair: unknown verb '" << args[1] << "'";
        for (std::size_t i = 0; i < near.size(); ++i) {
            std::cerr << (i == 0 ? "; did you mean " : i + 1 == near.size() ? " or " : ", ") << near[i];
        }
        std::cerr << (near.empty() ? "" : "?") << " (the verbs are";
        for (std::size_t i = 0; i < verbs.size(); ++i) std::cerr << (i ? ", " : " ") << verbs[i];
        std::cerr << "; 'vdbhair help VERB' explains one)\n";
        return 2;
    }
    std::vector<char*> argvNew;
    for (std::string& a : args) argvNew.push_back(a.data());

    std::string verb = "";
    try {
        app.parse(int(argvNew.size()), argvNew.data());
    } catch (const CLI::CallForHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForAllHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForVersion& e) {
        return app.exit(e);
    } catch (const CLI::ParseError& e) {
        for (const Command& c : commands) if (c.sub->parsed()) verb = c.sub->get_name();
        // One line, as every error (a script reading stderr gets the message and the hint together).
        std::cerr << "vdbhair" << (verb.empty() ? "" : " " + verb) << ": " << e.what() << " (run 'vdbhair"
                  << (verb.empty() ? "" : " " + verb) << " --help' for usage)\n";
        return 2;
    }

    for (const Command& c : commands) {
        if (!c.sub->parsed()) continue;
        verb = c.sub->get_name();
        if (common.threads < 0) {
            std::cerr << "vdbhair " << verb << ": --threads " << common.threads << ": must be 0 (all cores) or more\n";
            return 2;
        }
        setOverwritePolicy(common.noClobber ? OverwritePolicy::NoClobber : OverwritePolicy::Replace);
        std::unique_ptr<tbb::global_control> threads;
        if (common.threads > 0) {
            threads = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                            std::size_t(common.threads));
        }
        installInterruptHandlers(verb);
        keepUnwindReserve();
        TerminalProgress progress(verb, common.quiet);
        common.interrupter = &progress;
        // Errors: one line, after the progress line is erased, with the library's parameter names
        // spelled as this verb's flags.
        FlagNames flags = c.flags;
        flags.emplace_back("OverwritePolicy::NoClobber", "--no-clobber");
        auto fail = [&](int code, const std::string& message) {
            progress.clear();
            std::cerr << "vdbhair " << verb << ": " << withFlagNames(message, flags) << "\n";
            return code;
        };
        try {
            return c.run();
        } catch (const InterruptedError&) {  // 128 + the signal, as a shell reports it: 130 for Ctrl-C, 143 for SIGTERM
            return fail(128 + (interruptSignal() ? interruptSignal() : SIGINT), "interrupted; no partial output was written");
        } catch (const ValueError& e) {
            return fail(2, e.what());
        } catch (const Error& e) {
            return fail(1, e.what());
        } catch (const openvdb::Exception& e) {
            return fail(1, e.what());
        } catch (const std::bad_alloc&) {
            return fail(1, "out of memory");
        } catch (const std::exception& e) {
            return fail(1, e.what());
        }
    }
    return 2;
}

} // namespace vdbhair::app
