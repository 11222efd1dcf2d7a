/// @file BatchRecords.h
/// @brief The batch's record files: one JSON object a line, one line per finished input,
/// appended as the inputs finish (`OUTDIR/batch.jsonl`, or `batch.<I>-of-<N>.jsonl` per shard).
///
/// A record: `{"input", "output", "index", "job", "verb", "status": "ok"|"failed", "seconds",
/// "cpu_seconds", "peak_rss_kb", "exit_code" (or "signal" and "signal_name"), "report" (the verb's
/// --json object, or null), "error" (its one-line error, or null), "warnings" (its warning
/// lines), "finished" (UTC, ISO 8601)}`. Each line is appended by one write() and fsync(), so a
/// batch killed at any moment leaves at most a truncated last line; readers skip lines that are
/// not records and say how many they skipped.
#pragma once

#include <nlohmann/json.hpp>

#include <map>
#include <string>
#include <utility>
#include <vector>

namespace vdbhair::app {

struct RecordFile
{
    std::vector<nlohmann::json> records;  ///< in file order
    std::size_t skippedLines = 0;         ///< lines that are not records (a truncated last write)
};

/// @brief Read the records of @a path; a missing file has none.
/// @throw IoError if the file exists but cannot be read.
RecordFile readRecords(const std::string& path);

/// @brief The last record of each (input, job hash) among @a records.
std::map<std::pair<std::string, std::string>, nlohmann::json> latestRecords(const std::vector<nlohmann::json>& records);

/// @brief The dataset's manifest as CSV text: one row per record of @a records (their latest, as
/// latestRecords() gives them) in order of "index", then input; columns index, input, output,
/// status, seconds, error, then every number, string or boolean of the verb's report by its dotted
/// path (align.residual_rms), in the order first met; an array of numbers is one cell of its values
/// separated by spaces (align.matrix: 16 numbers, row by row); null and absent are empty cells.
std::string manifestCsv(const std::vector<nlohmann::json>& records);

/// @brief Appends records to a record file, each line with one write() and an fsync().
class RecordAppender
{
public:
    /// @brief Open (or create) @a path for appending; a last line without its newline (a killed
    /// writer's) is ended first, so that the next record starts on a line of its own.
    /// @throw IoError with the operating system's reason.
    explicit RecordAppender(std::string path);
    ~RecordAppender();
    RecordAppender(const RecordAppender&) = delete;
    RecordAppender& operator=(const RecordAppender&) = delete;

    /// @throw IoError if the line cannot be written or synced (disk full).
    void append(const nlohmann::json& record);

private:
    std::string mPath;
    int mFd = -1;
};

} // namespace vdbhair::app
