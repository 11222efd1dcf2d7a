/// @file Command.h
/// @brief What every `vdbhair` subcommand shares: the common options, how it registers, and
/// how it reports. Each subcommand lives in its own file under commands/, fills a plain
/// parameter struct from the command line and calls the library.
#pragma once

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <vdbhair/Progress.h>
#include <vdbhair/RunOptions.h>
#include <openvdb/openvdb.h>
#include <vdbhair/io/AxisName.h>
#include <vdbhair/io/ReadOptions.h>
#include <vdbhair/io/MeshFile.h>
#include <vdbhair/io/VdbInfo.h>
#include <vdbhair/strands/StrandSet.h>

#include <functional>
#include <iostream>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace vdbhair {
struct FieldParams;
struct SynthParams;
struct TransferParams;
}

namespace vdbhair::app {

/// Options every verb shares (docs/cli.md, "The vdbhair command"): the run's (RunOptions:
/// --threads, runParameters()) and the command line's own.
struct CommonOptions : RunOptions
{
    bool json = false;    ///< one JSON object on stdout instead of prose
    bool quiet = false;   ///< no progress, no warnings
    bool noClobber = false;  ///< refuse to replace existing outputs (--no-clobber)
    /// The progress bar and Ctrl-C (TerminalProgress.h), set by run() before the verb runs: hand it to
    /// every library call that takes an interrupter.
    WorkInterrupter* interrupter = nullptr;
    /// How strand files are read: the declared options (readParameters()) that addReadOptions()
    /// and addStrictOption() add (--points-per-strand, --curve-samples, --roots, --strict; --grid
    /// where a verb adds it).
    ReadOptions read;
    std::string rootsHead;        ///< the verb's --head, when it has one (for --roots auto)
    std::string rootsFlag = "--roots";  ///< the flag of `roots` (interpolate's: --root-end)
};

/// @brief Add the strand readers' options (--points-per-strand, --curve-samples, --roots) to a verb
/// that reads strand files. Call it after the verb's --head, if it has one: --roots auto then uses it.
void addReadOptions(CLI::App* sub, CommonOptions& common);

/// @brief Add --strict (readParameters()) to a verb that reads strand files and offers it.
void addStrictOption(CLI::App* sub, CommonOptions& common);

/// @brief The reader's options of @a common: the one place the command line becomes ReadOptions
/// (loadStrands(), info and convert start from it).
ReadOptions readOptions(const CommonOptions& common);

/// @brief A named step of a command that the library does not report on itself (reading or
/// writing a file): the progress line shows its name and the time spent. Null-safe.
class Stage
{
public:
    Stage(const CommonOptions& common, const std::string& name) : mI(common.interrupter)
    {
        if (mI) mI->start(name.c_str());
    }
    ~Stage()
    {
        if (mI) mI->end();
    }
    Stage(const Stage&) = delete;
    Stage& operator=(const Stage&) = delete;

private:
    WorkInterrupter* mI;
};

/// A registered subcommand: its CLI11 node and the function that runs it (returns the exit code).
/// The library's errors name parameters as ParamErrors (vdbhair/Parameters.h), which run() prints
/// with the flags' spelling.
struct Command
{
    CLI::App* sub = nullptr;
    std::function<int()> run;
};

/// @brief What a voxel size of 0 picks (suggestVoxelSize(), vdbhair/field/TangentField.h), for
/// the help of the verbs whose --voxel-size defaults to it.
inline const std::string kSuggestedVoxelSizeHelp = "3 x the median root spacing, within 1/64..1/4 of the head radius";

/// @brief Add --threads (runParameters()), --no-clobber, --json and --quiet to @a sub.
void addCommonOptions(CLI::App* sub, CommonOptions& common, bool withJson = true);

/// @brief Print a reader's warnings on stderr as `vdbhair <verb>: warning: ...` (unless quiet).
void printWarnings(const std::string& verb, const ReadReport& report, const CommonOptions& common);

/// @brief @a v as the user would type it (shortest form that reads back the same: 0.02, not 0.020000).
std::string formatValue(double v);

/// @brief Print @a j on stdout as one line.
void printJson(const nlohmann::json& j);

/// @brief The warning of `scalp` and `roots` when more than 1 % of a scalp's band (@a input's)
/// never crosses zero (ScalpArea): an open or inside-out part of a mesh, where no root can grow.
void warnBandWithoutZero(const std::string& verb, const std::string& input, double area, double areaWithoutZero,
                         const CommonOptions& common);

/// @brief Read strands from any supported file, printing the reader's warnings for @a verb.
/// Strands of fewer than two vertices are rejected under --strict (addStrictOption()).
/// @param vdbGrid for a .vdb file, the points grid holding the strands (`--grid`)
StrandSet loadStrands(const std::string& verb, const std::string& path, const CommonOptions& common,
                      const std::string& vdbGrid = ReadOptions{}.vdbGrid);

/// @brief Report the strands of zero length (every vertex at one point) that a verb using lengths
/// (field, refine, retrace; fit has its own rule, --skip-degenerate) was given: a warning naming them, an error under --strict, and
/// always an error when every strand has zero length (there would be nothing to write).
/// @throw FormatError naming @a path, the count and the first strands.
void checkStrandLengths(const std::string& verb, const std::string& path, const StrandSet& strands,
                        const CommonOptions& common);

/// @brief As loadStrands(), and a helicoid scene (.json) is grown first.
/// @param head when given and @a path is a scene with a "head" record, set to a mesh of that head
/// (makeSphereMesh()); left as it is otherwise.
StrandSet loadStrandsOrScene(const std::string& verb, const std::string& path, const CommonOptions& common,
                             const std::string& vdbGrid = "strands", TriangleMesh* head = nullptr);

/// @brief The scalp option of `field` and `refine` (with `--space scalp`; the space and the up
/// axis are the declared parameters of FieldParams, fieldParameters()).
struct ScalpOptions
{
    /// `CX,CY,CZ,R` (a sphere), or a scalp: a .vdb with a level set `surface` or a head mesh;
    /// empty: the sphere fitted to the roots
    std::string scalp;

    /// The sphere `--scalp` gives (cx, cy, cz, r), or empty when it names a file or is not given.
    /// @throw ValueError for numbers that are not four, or a radius that is not positive.
    std::vector<double> sphere() const;
};
void addScalpOptions(CLI::App* sub, ScalpOptions& opts);
/// @brief In scalp space (params.space), fill @a params' scalp from @a opts and params.scalp.up:
/// the sphere given, or fitted to the roots; with a scalp file, the scalp measured on its level
/// set (FieldParams::scalpSurface, on the sphere fitted to the roots).
/// @return the scalp's level set when `--scalp` named a file (for `refine`'s head), else null.
/// @throw ValueError for a bad sphere, or a scalp without scalp space; what reading the scalp throws.
openvdb::FloatGrid::Ptr applyScalpOptions(const ScalpOptions& opts, const StrandSet& strands, FieldParams& params,
                                          const CommonOptions& common);

/// A verb as `vdbhair --help` lists it.
struct Verb
{
    const char* name;
    const char* description;
};
/// @brief Every verb, in the order `vdbhair --help` lists them (Cli.cc: the one list of names and
/// descriptions, which both programs register).
const std::vector<Verb>& verbs();
/// @brief The subcommand @a name of @a app with its description from verbs().
/// @throw std::logic_error when verbs() has no such verb.
CLI::App* addVerb(CLI::App& app, const std::string& name);

// One function per subcommand file, each returning the registered command.
Command addInfoCommand(CLI::App& app, CommonOptions& common);
Command addCompareCommand(CLI::App& app, CommonOptions& common);
Command addConvertCommand(CLI::App& app, CommonOptions& common);
Command addDemoCommand(CLI::App& app, CommonOptions& common);
Command addFieldCommand(CLI::App& app, CommonOptions& common);
Command addRetraceCommand(CLI::App& app, CommonOptions& common);
Command addRefineCommand(CLI::App& app, CommonOptions& common);
Command addGrowCommand(CLI::App& app, CommonOptions& common);
Command addRenderCommand(CLI::App& app, CommonOptions& common);
Command addFitCommand(CLI::App& app, CommonOptions& common);
Command addInspectCommand(CLI::App& app, CommonOptions& common);
Command addScalpCommand(CLI::App& app, CommonOptions& common);
Command addRootsCommand(CLI::App& app, CommonOptions& common);
Command addInterpolateCommand(CLI::App& app, CommonOptions& common);
Command addReconstructCommand(CLI::App& app, CommonOptions& common);
Command addSynthCommand(CLI::App& app, CommonOptions& common);
Command addTransferCommand(CLI::App& app, CommonOptions& common);
Command addCombCommand(CLI::App& app, CommonOptions& common);
Command addBatchCommand(CLI::App& app, CommonOptions& common);
Command addPrepareCommand(CLI::App& app, CommonOptions& common);


/// @brief The scalp named by a verb's --scalp option (ScalpSurface.h's readScalp(), shown as a
/// stage), or null when @a path is empty.
openvdb::FloatGrid::Ptr readScalpOption(const std::string& path, const CommonOptions& common);

/// @brief Write a synthesized hairstyle (`synth`, `transfer`): a `.vdb`'s points carry each
/// strand's cluster at every coarser level (int32 cluster_level_1, ...); other formats the strands.
void writeSynthStrands(const std::string& path, const StrandSet& strands,
                       const std::vector<std::vector<std::int32_t>>& clusterOf);

/// @brief `transfer DETAILS BASE` and `synth EXAMPLE --coarse BASE` (Transfer.cc).
struct TransferJob
{
    std::string verb, details, base, output, scalp, detailsLabel = "DETAILS", baseLabel = "BASE";
};
int runTransferJob(const TransferJob& job, TransferParams params, const CommonOptions& common);

/// @brief Every verb, registered on @a app in the order of verbs().
std::vector<Command> addCommands(CLI::App& app, CommonOptions& common);

/// @brief The verbs of @a verbs nearest to @a word (edit distance, a prefix counting as 1), for
/// "did you mean"; empty when none is close.
std::vector<std::string> nearestVerbs(const std::string& word, const std::vector<std::string>& verbs);

/// @brief Parse, dispatch, and turn errors into `vdbhair <verb>: <message>` with an exit code:
/// 0 success, 1 a failed run (bad input file, I/O), 2 a bad command line, 130 interrupted
/// (Ctrl-C: nothing written): the program's main.
int run(int argc, char** argv);

} // namespace vdbhair::app
