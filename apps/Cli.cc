// The command line (Command.h): the verbs' table, the options every verb shares, and parsing and
// dispatch with the one-line errors and exit codes.
#include "Command.h"
#include "HeadOptions.h"
#include "ParamOptions.h"
#include "TerminalProgress.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/Version.h>
#include <vdbhair/io/FileUtil.h>

#include <tbb/global_control.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <memory>
#include <new>

namespace vdbhair::app {

namespace {
/// Every verb in the order `vdbhair --help' lists them, with the line it says of each.
constexpr Verb kVerbs[] = {
    {"info", "Summarize a strand file or list the grids of a .vdb file"},
    {"convert", "Convert strands between formats (several inputs are concatenated)"},
    {"field", "Estimate the robust tangent field of a hairstyle (Wang et al. 2009, Eq. 9) as VDB grids"},
    {"retrace", "Retrace every strand through a vector field from its root, for its own length"},
    {"refine", "Refine a hairstyle through its own tangent field: estimate, retrace, repeat from coarse to fine"},
    {"grow", "Grow the strands of a helicoid scene (guides, p-helicoid pieces, waviness, wisps)"},
    {"fit", "Fit p-helicoids to strands (Frechet measures, Nelder-Mead, piecewise); writes a scene"},
    {"scalp", "Make a scalp level set (grid 'surface') from a mesh, a sphere or oriented points, and a hair region (grid 'region')"},
    {"roots", "Spread follicles (roots) evenly over a scalp level set, in its region (Witkin & Heckbert 1994)"},
    {"interpolate", "New hairs between guide hairs: helicoid parameters blended by inverse distance (Piuze et al. 2011, 4), or guide points (--method points)"},
    {"reconstruct", "Rebuild a hairstyle from a share of its strands: fit them, interpolate the rest, measure both ways (Piuze et al. 2011, 5.4)"},
    {"synth", "A new hairstyle in the style of an example (Wang et al. 2009: clustering, feature-map synthesis, detail transfer, refinement)"},
    {"transfer", "BASE's global flow with DETAILS' wisps and curls (Wang et al. 2009, section 6): BASE keeps its coarsest level, the finer levels come from DETAILS by cluster-oriented detail transfer"},
    {"comb", "Detail-preserving combing (Wang et al. 2009, section 6): the coarsest wisps turn toward each stroke's direction, every strand follows its wisp with its own detail, lengths and roots kept"},
    {"compare", "Compare a hairstyle B with a reference A: oriented-point precision, recall and F1 (HairGS), Chamfer, strand-pair position, curvature and Frechet errors (Perm), shares leaving A's volume and entering a head"},
    {"prepare", "Make a hairstyle ready for a dataset: even roots (--strands), aligned to a common head (--align-to), resampled (--points), pushed out of the head (--fix-penetration)"},
    {"inspect", "Look into a .vdb file: value statistics, tiles, memory, bounds, leaf fill, metadata in words; slices as images"},
    {"render", "Preview strands as an image: lit fibres, depth-correct, anti-aliased"},
    {"demo", "The main job: refine a hairstyle through its own tangent field, all results in one folder"},
    {"batch", "Run one verb over a dataset: each input in its own process, records in OUTDIR/batch.jsonl, resumable, sharded for schedulers (Slurm arrays)"},
};
} // namespace

const std::vector<Verb>& verbs()
{
    static const std::vector<Verb> all(std::begin(kVerbs), std::end(kVerbs));
    return all;
}

CLI::App* addVerb(CLI::App& app, const std::string& name)
{
    for (const Verb& v : kVerbs) {
        if (name == v.name) return app.add_subcommand(v.name, v.description);
    }
    throw std::logic_error("vdbhair: verb '" + name + "' is not in the verbs' table (Cli.cc)");
}

void addCommonOptions(CLI::App* sub, CommonOptions& common, bool withJson)
{
    // Its range is checked in run() (one clear message instead of CLI11's range with a 309-digit bound).
    addParamOptions(sub, static_cast<RunOptions&>(common), runParameters());
    sub->add_flag("--no-clobber", common.noClobber, "Refuse to replace an existing output file (the default replaces it atomically)");
    if (withJson) sub->add_flag("--json", common.json, "Print one JSON object on stdout instead of prose");
    sub->add_flag("--quiet,-q", common.quiet, "No progress and no warnings on stderr");
}

void addReadOptions(CLI::App* sub, CommonOptions& common)
{
    ParamTable<ReadOptions> table = selectParams(readParameters(), {"points-per-strand", "curve-samples", "roots"});
    // interpolate's --roots names its root positions: there the option is only --root-end.
    const bool rootsTaken = sub->get_option_no_throw("--roots") != nullptr;
    for (Param<ReadOptions>& p : table) {
        if (p.name != "roots" || !rootsTaken) continue;
        p.name = "root-end";
        p.oldFlags.clear();
    }
    addParamOptions(sub, common.read, table);
    if (CLI::Option* head = sub->get_option_no_throw("--head")) head->each([&common](const std::string& path) { common.rootsHead = path; });
    if (rootsTaken) sub->preparse_callback([&common](std::size_t) { common.rootsFlag = "--root-end"; });
}

void addStrictOption(CLI::App* sub, CommonOptions& common)
{
    addParamOptions(sub, common.read, selectParams(readParameters(), {"strict"}));
}

ReadOptions readOptions(const CommonOptions& common)
{
    ReadOptions opts = common.read;
    opts.interrupter = common.interrupter;
    opts.spelling = ParamSpelling::Flag;
    opts.rootsName.flag = common.rootsFlag;
    if (opts.roots == RootEnd::Auto && !common.rootsHead.empty() && common.rootsHead != "none") {
        opts.rootsHeadDistance = headSurfaceDistance(common.rootsHead);
    }
    return opts;
}

void printWarnings(const std::string& verb, const ReadReport& report, const CommonOptions& common)
{
    if (common.quiet) return;
    // The readers spell their options as flags (readOptions() sets ReadOptions::spelling).
    for (const std::string& w : report.warnings) std::cerr << "vdbhair " << verb << ": warning: " << w << "\n";
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
    // A file name or a file's metadata need not be UTF-8: invalid bytes print as U+FFFD (valid
    // JSON) instead of ending the run, and a warning says so.
    std::cout << j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace) << std::endl;
    try {
        (void)j.dump();
    } catch (const nlohmann::json::type_error&) {
        std::cerr << "vdbhair: warning: the report holds text that is not UTF-8 (a file name or a metadata string); "
                     "its invalid bytes are written as U+FFFD\n";
    }
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

int run(int argc, char** argv)
{
    CLI::App app{"vdbhair " VDBHAIR_VERSION_STRING
                 ": hair geometry on OpenVDB - strands, tangent fields and generalized helicoids.\n"
                 "Formats: .hair .data .obj .ply .vdb .usda .abc (read and write), .usd (USD text) .tfx .bin .convdata (read).",
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
        try {
            checkParamOptions(runParameters(), static_cast<const RunOptions&>(common));
        } catch (const ValueError& e) {
            std::cerr << "vdbhair " << verb << ": " << spelledMessage(e, ParamSpelling::Flag) << "\n";
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
        // Errors: one line, after the progress line is erased, the parameters a library error
        // names (ParamError) spelled as flags.
        auto fail = [&](int code, const std::string& message) {
            progress.clear();
            std::cerr << "vdbhair " << verb << ": " << message << "\n";
            return code;
        };
        const auto flagged = [](const std::exception& e) { return spelledMessage(e, ParamSpelling::Flag); };
        try {
            return c.run();
        } catch (const InterruptedError&) {  // 128 + the signal, as a shell reports it: 130 for Ctrl-C, 143 for SIGTERM
            return fail(128 + (interruptSignal() ? interruptSignal() : SIGINT), "interrupted; no partial output was written");
        } catch (const ValueError& e) {
            return fail(2, flagged(e));
        } catch (const Error& e) {
            return fail(1, flagged(e));
        } catch (const std::bad_alloc&) {
            return fail(1, "out of memory");
        } catch (const std::exception& e) {
            return fail(1, flagged(e));
        }
    }
    return 2;
}

} // namespace vdbhair::app
