#include "BatchJob.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/io/JsonFile.h>

#include <nlohmann/json.hpp>

#include <glob.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>

namespace fs = std::filesystem;

namespace vdbhair::app {

namespace {

/// @a p made absolute against @a folder and normalized ("a/./b/../c" -> "a/c").
std::string resolve(const std::string& p, const fs::path& folder)
{
    const fs::path path(p);
    return (path.is_absolute() ? path : folder / path).lexically_normal().string();
}

/// FNV-1a, 64 bits, as 16 hex digits: a stable name for a job's settings (not a security hash).
std::string fnv1aHex(const std::string& text)
{
    std::uint64_t h = 14695981039346656037ull;
    for (unsigned char c : text) {
        h ^= c;
        h *= 1099511628211ull;
    }
    char buf[17];
    std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
    return buf;
}

std::vector<std::string> expandGlob(const std::string& pattern, const fs::path& folder, const std::string& where)
{
    const std::string full = resolve(pattern, folder);
    glob_t g{};
    const int rc = ::glob(full.c_str(), 0, nullptr, &g);  // unreadable folders are passed over
    std::vector<std::string> out;
    if (rc == 0) {
        for (std::size_t i = 0; i < g.gl_pathc; ++i) {
            if (fs::is_regular_file(g.gl_pathv[i])) out.push_back(fs::path(g.gl_pathv[i]).lexically_normal().string());
        }
    }
    globfree(&g);
    if (rc == GLOB_NOSPACE) throw ValueError(where + ": \"inputs\": out of memory expanding the pattern '" + pattern + "'");
    if (out.empty()) throw ValueError(where + ": \"inputs\": the pattern '" + pattern + "' (" + full + ") matches no file");
    return out;
}

std::vector<std::string> readListFile(const std::string& listPath, const fs::path& folder, const std::string& where)
{
    const std::string full = resolve(listPath, folder);
    std::ifstream f(full);
    if (!f) throw ValueError(where + ": \"inputs\": cannot read the list file '" + full + "'");
    const fs::path listFolder = fs::path(full).parent_path();
    std::vector<std::string> out;
    std::string line;
    while (std::getline(f, line)) {
        // Blank lines and '#' comments are skipped; surrounding spaces are not part of a path.
        const std::size_t a = line.find_first_not_of(" \t\r"), b = line.find_last_not_of(" \t\r");
        if (a == std::string::npos || line[a] == '#') continue;
        out.push_back(resolve(line.substr(a, b - a + 1), listFolder));
    }
    if (out.empty()) throw ValueError(where + ": \"inputs\": the list file '" + full + "' names no file");
    return out;
}

std::vector<std::string> readInputs(const nlohmann::json& inputs, const fs::path& folder, const std::string& where)
{
    if (inputs.is_string()) return expandGlob(inputs.get<std::string>(), folder, where);
    if (inputs.is_array()) {
        std::vector<std::string> out;
        for (std::size_t i = 0; i < inputs.size(); ++i) {
            if (!inputs[i].is_string() || inputs[i].get<std::string>().empty()) {
                throw ValueError(where + ": \"inputs\"[" + std::to_string(i) + "] is " + inputs[i].dump() + "; every input is a non-empty path string");
            }
            out.push_back(resolve(inputs[i].get<std::string>(), folder));
        }
        if (out.empty()) throw ValueError(where + ": \"inputs\" is an empty list; name at least one file");
        return out;
    }
    if (inputs.is_object()) {
        if (inputs.size() != 1 || !inputs.contains("list") || !inputs["list"].is_string()) {
            throw ValueError(where + ": \"inputs\" is " + inputs.dump() + "; an object must be {\"list\": \"PATHS.txt\"} (one path a line)");
        }
        return readListFile(inputs["list"].get<std::string>(), folder, where);
    }
    throw ValueError(where + ": \"inputs\" is " + inputs.dump() +
                     "; it must be a list of paths, a glob pattern (\"styles/*.data\") or {\"list\": \"PATHS.txt\"}");
}

void checkArgs(const std::vector<std::string>& args, const std::string& where)
{
    for (const std::string& a : args) {
        const bool output = a == "-o" || a == "--output" || a.rfind("--output=", 0) == 0 || (a.rfind("-o", 0) == 0 && a.size() > 2 && a[2] != '-');
        if (output) throw ValueError(where + ": \"args\" has '" + a + "'; batch names each output itself by \"output\"");
        if (a == "--json") throw ValueError(where + ": \"args\" has '--json'; batch passes it to every run itself (the report goes in the records)");
        if (a == "--help" || a == "-h") throw ValueError(where + ": \"args\" has '" + a + "'; run 'vdbhair VERB --help' for a verb's options");
    }
}

} // namespace

const std::vector<std::string>& batchVerbs()
{
    static const std::vector<std::string> verbs{"convert", "field",       "refine", "retrace", "fit",   "render", "grow",
                                                "reconstruct", "interpolate", "synth", "comb", "scalp", "roots", "prepare"};
    return verbs;
}

std::string expandPlaceholders(const std::string& text, const BatchItem& item, const std::string& outDir, const std::string& where)
{
    const fs::path input(item.input);
    std::string out;
    for (std::size_t pos = 0; pos < text.size();) {
        if (text[pos] != '{') {
            out += text[pos++];
            continue;
        }
        const std::size_t close = text.find('}', pos);
        if (close == std::string::npos) throw ValueError(where + ": '" + text + "' has a '{' without its '}'; the placeholders are {stem}, {name}, {index}" + (outDir.empty() ? "" : ", {outdir}"));
        const std::string key = text.substr(pos + 1, close - pos - 1);
        if (key == "stem") out += input.stem().string();
        else if (key == "name") out += input.filename().string();
        else if (key == "index") out += std::to_string(item.index);
        else if (key == "outdir" && !outDir.empty()) out += outDir;
        else {
            throw ValueError(where + ": '" + text + "' has the unknown placeholder {" + key + "}; the placeholders are {stem}, {name}, {index}" +
                             (outDir.empty() ? " ({outdir} only in \"args\")" : ", {outdir}"));
        }
        pos = close + 1;
    }
    return out;
}

BatchJob readBatchJob(const std::string& path)
{
    const std::string where = path;
    nlohmann::json doc;
    try {
        doc = readJsonFile(path, 16, "a batch JOB");
    } catch (const Error& e) {
        throw ValueError(e.what());
    }
    if (!doc.is_object()) throw ValueError(where + ": a JOB is a JSON object with \"inputs\", \"verb\", \"args\" and \"output\"");
    static const std::vector<std::string> keys{"inputs", "verb", "args", "output"};
    for (auto it = doc.begin(); it != doc.end(); ++it) {
        if (std::find(keys.begin(), keys.end(), it.key()) == keys.end()) {
            throw ValueError(where + ": unknown key \"" + it.key() + "\"; a JOB has \"inputs\", \"verb\", \"args\" (optional) and \"output\"");
        }
    }
    for (const char* k : {"inputs", "verb", "output"}) {
        if (!doc.contains(k)) throw ValueError(where + ": \"" + k + "\" is missing; a JOB has \"inputs\", \"verb\", \"args\" (optional) and \"output\"");
    }

    BatchJob job;
    job.path = path;
    const fs::path folder = fs::absolute(fs::path(path)).parent_path().lexically_normal();
    job.folder = folder.string();

    // The verb and its options.
    if (!doc["verb"].is_string()) throw ValueError(where + ": \"verb\" is " + doc["verb"].dump() + "; it must be a verb's name");
    job.verb = doc["verb"].get<std::string>();
    const std::vector<std::string>& verbs = batchVerbs();
    if (std::find(verbs.begin(), verbs.end(), job.verb) == verbs.end()) {
        std::string list;
        for (const std::string& v : verbs) list += (list.empty() ? "" : ", ") + v;
        throw ValueError(where + ": \"verb\" '" + job.verb + "' is not a verb batch runs (one input, one output): " + list);
    }
    if (doc.contains("args")) {
        const nlohmann::json& a = doc["args"];
        if (!a.is_array()) throw ValueError(where + ": \"args\" is " + a.dump() + "; it must be a list of strings, as on the command line: [\"--voxel-size\", \"0.5\"]");
        for (std::size_t i = 0; i < a.size(); ++i) {
            if (!a[i].is_string()) {
                throw ValueError(where + ": \"args\"[" + std::to_string(i) + "] is " + a[i].dump() + "; every argument is a string, as on the command line (\"0.5\", not 0.5)");
            }
            job.args.push_back(a[i].get<std::string>());
        }
    }
    checkArgs(job.args, where);

    // The naming rule: a file name in the output folder.
    if (!doc["output"].is_string() || doc["output"].get<std::string>().empty()) {
        throw ValueError(where + ": \"output\" is " + doc["output"].dump() + "; it must be a naming rule such as \"{stem}.vdb\"");
    }
    job.outputRule = doc["output"].get<std::string>();
    if (job.outputRule.find('/') != std::string::npos) {
        throw ValueError(where + ": \"output\" '" + job.outputRule + "' has a '/'; it names a file in the output folder (-o OUTDIR), e.g. \"{stem}.vdb\"");
    }
    const BatchItem probe{0, "/x/probe.hair", "", {}};
    expandPlaceholders(job.outputRule, probe, "", where + ": \"output\"");
    for (const std::string& a : job.args) expandPlaceholders(a, probe, "/outdir", where + ": \"args\"");

    // The inputs: sorted and each once, so that shards and {index} do not depend on the listing's order.
    job.inputs = readInputs(doc["inputs"], folder, where);
    std::sort(job.inputs.begin(), job.inputs.end());
    job.inputs.erase(std::unique(job.inputs.begin(), job.inputs.end()), job.inputs.end());
    if (job.inputs.size() > 1 && job.outputRule.find("{stem}") == std::string::npos && job.outputRule.find("{name}") == std::string::npos &&
        job.outputRule.find("{index}") == std::string::npos) {
        throw ValueError(where + ": \"output\" '" + job.outputRule + "' names one file for " + std::to_string(job.inputs.size()) +
                         " inputs; use {stem}, {name} or {index}");
    }

    job.hash = fnv1aHex(nlohmann::json{{"verb", job.verb}, {"args", job.args}, {"output", job.outputRule}}.dump());
    return job;
}

std::vector<BatchItem> planBatch(const BatchJob& job, const std::string& outDir)
{
    std::vector<BatchItem> items;
    std::map<std::string, std::size_t> byOutput;
    for (std::size_t i = 0; i < job.inputs.size(); ++i) {
        BatchItem item{i, job.inputs[i], "", {}};
        const std::string name = expandPlaceholders(job.outputRule, item, "", job.path + ": \"output\"");
        if (name == "." || name == ".." || name.empty()) throw ValueError(job.path + ": \"output\" gives '" + name + "' for " + item.input + "; it must name a file");
        if (name.rfind("batch", 0) == 0 && fs::path(name).extension() == ".jsonl") {
            throw ValueError(job.path + ": \"output\" gives '" + name + "', the name of batch's own records; choose another rule");
        }
        item.output = (fs::path(outDir) / name).string();
        for (const std::string& a : job.args) {
            if (a.rfind("{outdir}/", 0) == 0) item.moreOutputs.push_back(expandPlaceholders(a, item, outDir, job.path + ": \"args\""));
        }
        const auto [it, added] = byOutput.emplace(item.output, i);
        if (!added) {
            throw ValueError(job.path + ": \"output\" '" + job.outputRule + "' maps both " + job.inputs[it->second] + " and " + item.input + " to " +
                             name + "; every input needs its own output (use {index} or {name})");
        }
        items.push_back(std::move(item));
    }
    return items;
}

bool outputsExist(const BatchItem& item, std::string* missing)
{
    if (!fs::exists(item.output)) {
        if (missing) *missing = item.output;
        return false;
    }
    for (const std::string& f : item.moreOutputs) {
        if (!fs::exists(f)) {
            if (missing) *missing = f;
            return false;
        }
    }
    return true;
}

} // namespace vdbhair::app
