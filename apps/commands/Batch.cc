// vdbhair batch JOB.json -o OUTDIR: one verb over a dataset, each input in a process of its own,
// with records, resumption and shards for schedulers (Slurm arrays); vdbhair batch --merge OUTDIR.
#include "../AppParameters.h"
#include "../Command.h"
#include "../ParamOptions.h"
#include "../TerminalProgress.h"
#include "../batch/BatchJob.h"
#include "../batch/BatchRecords.h"
#include "../batch/BatchShard.h"
#include "../batch/ChildProcess.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/io/FileUtil.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <thread>

#include <unistd.h>

namespace fs = std::filesystem;

namespace vdbhair::app {

namespace {

struct BatchCmdParams
{
    std::string job, outDir, merge, shard;
    BatchParams run;  ///< its declared parameters (batchParameters()) are options
};

using Clock = std::chrono::steady_clock;

/// The verbs' registrations, to check a JOB's "args" with the verb's own parser before any run.
using AddCommand = Command (*)(CLI::App&, CommonOptions&);
const std::map<std::string, AddCommand>& verbParsers()
{
    static const std::map<std::string, AddCommand> parsers{
        {"convert", addConvertCommand}, {"field", addFieldCommand},         {"refine", addRefineCommand},
        {"retrace", addRetraceCommand}, {"fit", addFitCommand},             {"render", addRenderCommand},
        {"grow", addGrowCommand},       {"reconstruct", addReconstructCommand}, {"interpolate", addInterpolateCommand},
        {"synth", addSynthCommand},     {"comb", addCombCommand},           {"scalp", addScalpCommand},
        {"roots", addRootsCommand}, {"prepare", addPrepareCommand}};
    return parsers;
}

/// The command line of one input: VERB INPUT -o OUTPUT ARGS... --json (program name first).
std::vector<std::string> childCommand(const std::string& program, const BatchJob& job, const BatchItem& item,
                                      const std::string& outDir, const std::vector<std::string>& extra)
{
    std::vector<std::string> argv{program, job.verb, item.input, "-o", item.output};
    for (const std::string& a : job.args) argv.push_back(expandPlaceholders(a, item, outDir, job.path + ": \"args\""));
    argv.insert(argv.end(), extra.begin(), extra.end());
    argv.push_back("--json");
    return argv;
}

/// Parse the first input's command line with the verb's own parser (a fresh registration), so a
/// misspelt option fails once, up front, instead of once per input.
void checkVerbArgs(const BatchJob& job, const std::vector<std::string>& argv)
{
    CommonOptions common;
    CLI::App scratch{"", "vdbhair"};
    const Command verb = verbParsers().at(job.verb)(scratch, common);  // holds the options' parameters
    std::vector<std::string> reversed(argv.begin() + 1, argv.end());
    std::reverse(reversed.begin(), reversed.end());
    try {
        scratch.parse(reversed);
    } catch (const CLI::ParseError& e) {
        throw ValueError(job.path + ": \"args\" for " + job.verb + ": " + e.what() + " (run 'vdbhair " + job.verb + " --help' for its options)");
    }
}

/// The lines of a small text file (a child's captured output), without empty ones.
std::vector<std::string> readLines(const std::string& path)
{
    std::ifstream f(path, std::ios::binary);
    std::vector<std::string> lines;
    std::string line;
    while (std::getline(f, line)) {
        if (!line.empty() && line.back() == '\r') line.pop_back();
        if (!line.empty()) lines.push_back(line);
    }
    return lines;
}

std::string utcNow()
{
    const std::time_t t = std::time(nullptr);
    std::tm tm{};
    gmtime_r(&t, &tm);
    char buf[32];
    std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
    return buf;
}

/// A running child and what it is doing.
struct Running
{
    BatchItem item;
    Clock::time_point start;
    std::string outPath, errPath;
};

/// The record of a finished child (BatchRecords.h).
nlohmann::json makeRecord(const BatchJob& job, const Running& run, const ChildExit& exit)
{
    const double seconds = std::chrono::duration<double>(Clock::now() - run.start).count();
    const std::vector<std::string> out = readLines(run.outPath), err = readLines(run.errPath);
    nlohmann::json report = nullptr;
    if (!out.empty()) {
        report = nlohmann::json::parse(out.back(), nullptr, /*allow_exceptions=*/false);
        if (report.is_discarded()) report = nullptr;
    }
    nlohmann::json warnings = nlohmann::json::array();
    for (const std::string& line : err) {
        if (line.find(": warning: ") != std::string::npos && warnings.size() < 20) warnings.push_back(line);
    }
    std::string missing;
    const bool wrote = outputsExist(run.item, &missing);
    const bool ok = exit.exitCode == 0 && wrote;
    nlohmann::json error = nullptr;
    if (!ok) {
        if (!err.empty() && err.back().find(": warning: ") == std::string::npos) error = err.back();
        else if (exit.signal) error = "killed by " + signalName(exit.signal) + (exit.signal == SIGKILL ? " (out of memory?)" : "");
        else if (exit.exitCode == 0) error = "exited with status 0 but wrote no " + missing;
        else error = "exited with status " + std::to_string(exit.exitCode) + " and no message";
    }
    nlohmann::json r = {{"input", run.item.input}, {"output", run.item.output}, {"more_outputs", run.item.moreOutputs}, {"index", run.item.index}, {"job", job.hash},
                        {"verb", job.verb},        {"status", ok ? "ok" : "failed"}, {"seconds", seconds},
                        {"cpu_seconds", exit.cpuSeconds}, {"peak_rss_kb", exit.peakRssKb}, {"report", report},
                        {"error", error},          {"warnings", warnings}, {"finished", utcNow()}};
    if (exit.signal) {
        r["signal"] = exit.signal;
        r["signal_name"] = signalName(exit.signal);
    } else {
        r["exit_code"] = exit.exitCode;
    }
    return r;
}

/// Counts of a run or of merged records, and its failures.
struct Summary
{
    std::size_t inputs = 0, ok = 0, failed = 0, skipped = 0, notRun = 0;
    double seconds = 0.0, cpuSeconds = 0.0;
    long peakRssKb = 0;
    std::vector<std::pair<std::string, std::string>> failures;  ///< input, error

    void add(const nlohmann::json& record)
    {
        if (record["status"] == "ok") ++ok;
        else {
            ++failed;
            failures.emplace_back(record["input"].get<std::string>(), record["error"].is_string() ? record["error"].get<std::string>() : "");
        }
        if (record.contains("cpu_seconds") && record["cpu_seconds"].is_number()) cpuSeconds += record["cpu_seconds"].get<double>();
        if (record.contains("peak_rss_kb") && record["peak_rss_kb"].is_number()) peakRssKb = std::max(peakRssKb, record["peak_rss_kb"].get<long>());
    }
};

/// The summary on stderr (prose, unless --quiet) and, with --json, on stdout.
void printSummary(const Summary& s, nlohmann::json extra, const std::string& recordsPath, const CommonOptions& common)
{
    if (!common.quiet) {
        std::ostringstream o;
        o << "vdbhair batch: " << s.inputs << " input(s): " << s.ok << " ok, " << s.failed << " failed";
        if (s.skipped) o << ", " << s.skipped << " already done";
        if (s.notRun) o << ", " << s.notRun << " not run";
        o << " in " << formatValue(std::round(s.seconds * 100.0) / 100.0) << " s (CPU " << formatValue(std::round(s.cpuSeconds * 100.0) / 100.0)
          << " s, largest process " << (s.peakRssKb + 512) / 1024 << " MiB); records in " << recordsPath << "\n";
        const std::size_t shown = std::min<std::size_t>(s.failures.size(), 20);
        for (std::size_t i = 0; i < shown; ++i) o << "  failed: " << s.failures[i].first << ": " << s.failures[i].second << "\n";
        if (s.failures.size() > shown) o << "  ... and " << s.failures.size() - shown << " more failures (see the records)\n";
        std::cerr << o.str();
    }
    if (common.json) {
        nlohmann::json failures = nlohmann::json::array();
        for (const auto& [input, error] : s.failures) failures.push_back({{"input", input}, {"error", error}});
        extra.update({{"inputs", s.inputs}, {"ok", s.ok}, {"failed", s.failed}, {"skipped", s.skipped}, {"not_run", s.notRun},
                      {"seconds", s.seconds}, {"cpu_seconds", s.cpuSeconds}, {"peak_rss_kb", s.peakRssKb},
                      {"failures", failures}, {"records", recordsPath}});
        std::cout << extra.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace) << std::endl;
    }
}

/// OUTDIR/manifest.csv (manifestCsv()): the latest record of each input, of the job @a hash (all
/// jobs when empty), from the records of @a recordsPath. @return its path.
std::string writeManifest(const std::string& outDir, const std::string& recordsPath, const std::string& hash)
{
    std::vector<nlohmann::json> latest;
    for (auto& [key, record] : latestRecords(readRecords(recordsPath).records)) {
        if (hash.empty() || key.second == hash) latest.push_back(record);
    }
    const std::string path = (fs::path(outDir) / "manifest.csv").string();
    writeFileAtomic(path, manifestCsv(latest), "batch: manifest");
    return path;
}

/// --merge OUTDIR: the shards' records joined into OUTDIR/batch.jsonl.
int runMerge(const std::string& outDir, const CommonOptions& common)
{
    if (!fs::is_directory(outDir)) throw ValueError("--merge " + outDir + ": not a folder");
    // The shard files, by their count N: one complete set is expected.
    std::map<std::size_t, std::map<std::size_t, std::string>> byCount;
    for (const fs::directory_entry& e : fs::directory_iterator(outDir)) {
        if (const auto s = shardOfRecordFile(e.path().filename().string())) byCount[s->count][s->index] = e.path().string();
    }
    if (byCount.empty()) throw IoError(outDir + ": no shard records (batch.I-of-N.jsonl) to merge; run 'vdbhair batch JOB -o " + outDir + " --shard I/N' first");
    if (byCount.size() > 1) {
        std::string counts;
        for (const auto& [n, files] : byCount) counts += (counts.empty() ? "" : ", ") + std::to_string(files.size()) + " of " + std::to_string(n);
        throw IoError(outDir + ": shard records of different splits (" + counts + " shards); remove the stale ones and merge one split");
    }
    const auto& [count, files] = *byCount.begin();
    std::string missing;
    for (std::size_t i = 0; i < count; ++i) {
        if (!files.count(i)) missing += (missing.empty() ? "" : ", ") + BatchShard{i, count}.recordFileName();
    }
    if (!missing.empty()) throw IoError(outDir + ": " + missing + " missing; every shard of " + std::to_string(count) + " must run before --merge");

    // batch.jsonl's records first (a record appended after an earlier merge stays), then each
    // shard's in shard order, each record once.
    const std::string mergedPath = (fs::path(outDir) / "batch.jsonl").string();
    std::vector<nlohmann::json> merged;
    std::set<std::string> seen;
    std::size_t skippedLines = 0;
    auto take = [&](const std::string& path) {
        RecordFile f = readRecords(path);
        skippedLines += f.skippedLines;
        for (nlohmann::json& r : f.records) {
            if (seen.insert(r.dump()).second) merged.push_back(std::move(r));
        }
    };
    take(mergedPath);
    for (const auto& [index, path] : files) take(path);
    std::string text;
    for (const nlohmann::json& r : merged) text += r.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
    writeFileAtomic(mergedPath, text, "batch --merge");

    // The summary: the latest record of each input (and job).
    Summary s;
    for (const auto& [key, record] : latestRecords(merged)) {
        ++s.inputs;
        s.add(record);
        if (record.contains("seconds") && record["seconds"].is_number()) s.seconds += record["seconds"].get<double>();
    }
    if (skippedLines && !common.quiet) {
        std::cerr << "vdbhair batch: warning: " << skippedLines << " line(s) of the shard records are not records (a run killed while writing); skipped\n";
    }
    const std::string manifest = writeManifest(outDir, mergedPath, "");
    printSummary(s, {{"merged", count}, {"manifest", manifest}}, mergedPath, common);
    return s.failed ? 1 : 0;
}

int runBatch(const BatchCmdParams& p, const CommonOptions& common)
{
    checkParamOptions(batchParameters(), p.run);
    if (!p.merge.empty()) {
        if (!p.job.empty() || !p.outDir.empty() || !p.shard.empty() || p.run.retryFailed) {
            throw ValueError("--merge OUTDIR takes no JOB, -o, --shard or --retry-failed");
        }
        return runMerge(p.merge, common);
    }
    if (p.job.empty()) throw ValueError("needs a JOB file: vdbhair batch JOB.json -o OUTDIR (or --merge OUTDIR)");
    if (p.outDir.empty()) throw ValueError("needs an output folder: -o OUTDIR");

    // Everything is checked before anything runs.
    const BatchJob job = readBatchJob(p.job);
    const BatchShard shard = !p.shard.empty() ? parseShard(p.shard) : shardFromSlurm().value_or(BatchShard{});
    const std::string outDir = fs::absolute(p.outDir).lexically_normal().string();
    const std::vector<BatchItem> items = planBatch(job, outDir);
    const unsigned cores = std::max(1u, std::thread::hardware_concurrency());
    const std::size_t jobs = p.run.jobs > 0 ? std::size_t(p.run.jobs) : cores;
    // Each child gets its share of the cores unless the JOB says otherwise (results do not
    // depend on the thread count).
    std::vector<std::string> extra;
    if (std::find(job.args.begin(), job.args.end(), "--threads") == job.args.end()) {
        extra = {"--threads", std::to_string(common.threads > 0 ? std::size_t(common.threads) : std::max<std::size_t>(1, cores / jobs))};
    }
    if (common.noClobber) extra.push_back("--no-clobber");
    const std::string program = fs::read_symlink("/proc/self/exe").string();
    checkVerbArgs(job, childCommand(program, job, items.front(), outDir, extra));
    std::error_code ec;
    fs::create_directories(outDir, ec);
    if (!fs::is_directory(outDir)) throw IoError("-o " + p.outDir + ": cannot create the output folder" + (ec ? ": " + ec.message() : ""));

    // What is left to do: a record that says ok, of this job, with its output present, is done.
    const std::string recordsPath = (fs::path(outDir) / shard.recordFileName()).string();
    RecordFile previous = readRecords(recordsPath);
    if (shard.sharded()) {  // a merged file counts too
        RecordFile merged = readRecords((fs::path(outDir) / "batch.jsonl").string());
        previous.records.insert(previous.records.begin(), merged.records.begin(), merged.records.end());
    }
    const auto latest = latestRecords(previous.records);
    Summary s;
    std::vector<BatchItem> todo;
    for (const BatchItem& item : items) {
        if (!shard.holds(item.index)) continue;
        ++s.inputs;
        const auto it = latest.find({item.input, job.hash});
        const bool done = it != latest.end() && it->second["status"] == "ok" && outputsExist(item);
        const bool failed = it != latest.end() && it->second["status"] == "failed";
        if (done) ++s.skipped;
        else if (p.run.retryFailed && !failed) ++s.notRun;
        else todo.push_back(item);
    }
    if (previous.skippedLines && !common.quiet) {
        std::cerr << "vdbhair batch: warning: " << recordsPath << ": " << previous.skippedLines
                  << " line(s) are not records (a run killed while writing); skipped, their inputs run again\n";
    }

    // Run: at most `jobs` children at once; a signal stops the launching, is passed on to the
    // running children, and their (interrupted, so unwritten) runs get no record.
    ::unsetenv("VDBHAIR_TEST_INTERRUPT_AFTER");  // the batch's own test hook, not its children's
    interruptBlockingCalls();
    RecordAppender appender(recordsPath);
    ProgressCounter progress(common.interrupter, "running inputs", todo.size(), "inputs");
    std::map<pid_t, Running> running;
    std::size_t next = 0;
    bool forwarded = false;
    const Clock::time_point t0 = Clock::now();
    while (next < todo.size() || !running.empty()) {
        while (!interruptRequested() && running.size() < jobs && next < todo.size()) {
            const BatchItem& item = todo[next++];
            const std::string stem = (fs::path(outDir) / ("." + shard.recordFileName() + "." + std::to_string(item.index))).string();
            Running r{item, Clock::now(), stem + ".out", stem + ".err"};
            const pid_t pid = startChild(childCommand(program, job, item, outDir, extra), job.folder, r.outPath, r.errPath);
            running.emplace(pid, std::move(r));
        }
        if (interruptRequested() && !forwarded) {
            for (const auto& [pid, r] : running) ::kill(pid, SIGTERM);
            forwarded = true;
        }
        if (running.empty()) break;
        ChildExit exit;
        if (!waitAnyChild(exit)) continue;  // a signal: passed on above
        const auto it = running.find(exit.pid);
        if (it == running.end()) continue;
        // A run the signal stopped (Ctrl-C on a terminal reaches the children too) wrote nothing and
        // gets no record: the next run does it.
        const bool stopped = interruptRequested() && (exit.signal == SIGTERM || exit.signal == SIGINT || exit.exitCode == 130 || exit.exitCode == 143);
        if (!stopped) {
            const nlohmann::json record = makeRecord(job, it->second, exit);
            appender.append(record);
            s.add(record);
            progress.add(1);
        }
        std::remove(it->second.outPath.c_str());
        std::remove(it->second.errPath.c_str());
        running.erase(it);
    }
    progress.finish();
    s.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
    s.notRun += todo.size() - s.ok - s.failed;

    nlohmann::json summaryJson = {{"job", job.path}, {"hash", job.hash}, {"verb", job.verb}, {"outdir", outDir}, {"jobs", jobs}};
    // A shard's manifest would list a part of the set (--merge writes the whole one); an
    // interrupted run writes nothing more (its next run does).
    const bool manifest = !shard.sharded() && !interruptRequested();
    summaryJson["manifest"] = manifest ? nlohmann::json(writeManifest(outDir, recordsPath, job.hash)) : nlohmann::json(nullptr);
    summaryJson["shard"] = shard.sharded() ? nlohmann::json(std::to_string(shard.index) + "/" + std::to_string(shard.count)) : nlohmann::json(nullptr);
    if (interruptRequested()) {
        // 128 + the signal, as a shell reports a process its signal ended: 130 SIGINT, 143 SIGTERM.
        summaryJson["interrupted"] = true;
        printSummary(s, summaryJson, recordsPath, common);
        std::cerr << "vdbhair batch: interrupted by " << signalName(interruptSignal()) << "; " << s.ok + s.failed
                  << " input(s) recorded, the other " << s.notRun << " run on the next run\n";
        return 128 + interruptSignal();
    }
    printSummary(s, summaryJson, recordsPath, common);
    return s.failed ? 1 : 0;
}

} // namespace

Command addBatchCommand(CLI::App& app, CommonOptions& common)
{
    auto params = std::make_shared<BatchCmdParams>();
    CLI::App* sub = addVerb(app, "batch");
    sub->add_option("job", params->job, "The JOB file (.json): inputs, verb, args, output; see below");
    sub->add_option("-o,--output", params->outDir, "Output folder (created if missing): the outputs and the records");
    addParamOptions(sub, params->run, batchParameters());
    sub->add_option("--shard", params->shard, "Run shard I of N (I/N, from 0): the inputs at sorted positions p with p mod N = I "
                                              "(default: SLURM_ARRAY_TASK_ID - SLURM_ARRAY_TASK_MIN of SLURM_ARRAY_TASK_COUNT in an array job)");
    sub->add_option("--merge", params->merge, "Join the shards' records OUTDIR/batch.I-of-N.jsonl into OUTDIR/batch.jsonl and print the summary");
    addCommonOptions(sub, common);
    sub->footer(
        "JOB (JSON; relative paths against the JOB's folder, where the runs start):\n"
        "  {\"inputs\": [\"a.hair\", \"b.data\"] | \"styles/*.data\" | {\"list\": \"paths.txt\"},\n"
        "   \"verb\": \"field\",  \"args\": [\"--voxel-size\", \"0.005\"],  \"output\": \"{stem}.vdb\"}\n"
        "Verbs: convert field refine retrace fit render grow reconstruct interpolate synth comb scalp roots prepare.\n"
        "Placeholders in output and args: {stem} {name} {index} (sorted position); in args also {outdir}.\n"
        "An arg that starts with {outdir}/ is a second output (e.g. --dense {outdir}/{stem}.npy).\n"
        "OUTDIR/manifest.csv lists every input's latest record with the verb's report flattened to columns\n"
        "(written after each unsharded run and by --merge).\n"
        "A rerun skips inputs recorded ok (for the same verb, args and output rule) whose outputs exist.\n"
        "Exit status: 0 every input ok, 1 an input failed (see the records), 2 a bad command line or JOB,\n"
        "130/143 interrupted by SIGINT/SIGTERM (finished inputs are recorded; the rest run on the next run).\n"
        "Example: vdbhair batch scenes/batch/field.json -o out --jobs 2; vdbhair batch --merge out");
    return {sub, [params, &common] { return runBatch(*params, common); }};
}

} // namespace vdbhair::app
