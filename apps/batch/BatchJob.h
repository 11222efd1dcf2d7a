/// @file BatchJob.h
/// @brief A batch JOB file (`vdbhair batch JOB.json`): which inputs, which verb with which
/// options, and how outputs are named; read and checked whole before anything runs.
///
/// ```json
/// {
///   "inputs": ["a.hair", "b.data"],            // or "styles/*.data", or {"list": "paths.txt"}
///   "verb": "field",
///   "args": ["--voxel-size", "0.005", "--dense", "{outdir}/{stem}.npy", "--dense-box", "-0.3,-0.3,-0.3,0.3,0.3,0.3"],
///   "output": "{stem}.vdb"
/// }
/// ```
/// Relative paths (inputs, the glob, the list file) resolve against the JOB file's folder; the
/// paths in a list file against the list file's folder; the children run in the JOB's folder, so
/// relative paths in `args` mean the same. Placeholders, in `output` and in `args`: `{stem}` (the
/// input's file name without its last extension), `{name}` (with it), `{index}` (the input's
/// position in the sorted input list, from 0; the same in every shard), and in `args` only
/// `{outdir}` (the output folder, absolute). An argument that starts with `{outdir}/` names a
/// second output of the verb (e.g. `--dense {outdir}/{stem}.npy`): an input is done only when its
/// output and every such file exist.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace vdbhair::app {

/// @brief The verbs a batch runs: each reads one input and writes one output (`-o`).
const std::vector<std::string>& batchVerbs();

struct BatchJob
{
    std::string path;                 ///< the JOB file, as given
    std::string folder;               ///< its folder, absolute: relative paths resolve against it
    std::string verb;
    std::vector<std::string> args;    ///< the verb's options as on its command line (placeholders unexpanded)
    std::string outputRule;           ///< e.g. "{stem}.vdb"
    std::vector<std::string> inputs;  ///< absolute, normalized, sorted, each once
    std::string hash;                 ///< 16 hex digits of (verb, args, output rule): records of another job do not count
};

/// @brief One input of a batch and where its output goes.
struct BatchItem
{
    std::size_t index = 0;  ///< in BatchJob::inputs
    std::string input;      ///< absolute
    std::string output;     ///< absolute, in the output folder
    std::vector<std::string> moreOutputs;  ///< the arguments that start with {outdir}/, expanded
};

/// @brief Whether the output and every second output of @a item exist; else the first missing.
bool outputsExist(const BatchItem& item, std::string* missing = nullptr);

/// @brief Read, check and expand the JOB file @a path.
/// @throw ValueError, one line naming the JOB, the key and the rule: invalid JSON, an unknown
/// key, a missing or mistyped key, an unknown verb, options batch sets itself (-o, --json), a
/// bad placeholder, a naming rule with a folder in it, a glob or list naming no file.
BatchJob readBatchJob(const std::string& path);

/// @brief The items of @a job with outputs in @a outDir (absolute).
/// @throw ValueError naming both inputs when two map to the same output, or an output that is
/// the batch's own record file.
std::vector<BatchItem> planBatch(const BatchJob& job, const std::string& outDir);

/// @brief @a text with its placeholders replaced for @a item.
/// @throw ValueError for an unknown or unclosed placeholder (@a where names the place).
std::string expandPlaceholders(const std::string& text, const BatchItem& item, const std::string& outDir, const std::string& where);

} // namespace vdbhair::app
