#include "BatchShard.h"

#include <vdbhair/Exceptions.h>

#include <cstdlib>
#include <regex>

namespace vdbhair::app {

namespace {

/// A whole number of at most 9 digits, or nothing.
std::optional<std::size_t> parseCount(const std::string& s)
{
    if (s.empty() || s.size() > 9 || s.find_first_not_of("0123456789") != std::string::npos) return std::nullopt;
    return std::size_t(std::stoul(s));
}

} // namespace

std::string BatchShard::recordFileName() const
{
    if (!sharded()) return "batch.jsonl";
    return "batch." + std::to_string(index) + "-of-" + std::to_string(count) + ".jsonl";
}

BatchShard parseShard(const std::string& text)
{
    const std::size_t slash = text.find('/');
    const auto i = slash == std::string::npos ? std::nullopt : parseCount(text.substr(0, slash));
    const auto n = slash == std::string::npos ? std::nullopt : parseCount(text.substr(slash + 1));
    if (!i || !n || *n == 0 || *i >= *n) {
        throw ValueError("--shard '" + text + "': must be I/N with 0 <= I < N (shard I of N, counted from 0), e.g. 0/4");
    }
    return {*i, *n};
}

std::optional<BatchShard> shardFromSlurm()
{
    const char* id = std::getenv("SLURM_ARRAY_TASK_ID");
    if (!id) return std::nullopt;
    const char* count = std::getenv("SLURM_ARRAY_TASK_COUNT");
    const char* min = std::getenv("SLURM_ARRAY_TASK_MIN");
    const std::optional<std::size_t> i = parseCount(id), n = parseCount(count ? count : ""), m = parseCount(min ? min : "0");
    const std::string values = std::string("SLURM_ARRAY_TASK_ID=") + id + ", SLURM_ARRAY_TASK_COUNT=" + (count ? count : "(unset)") +
                               ", SLURM_ARRAY_TASK_MIN=" + (min ? min : "(unset)");
    if (!i || !n || !m || *n == 0 || *i < *m || *i - *m >= *n) {
        throw ValueError("the Slurm array task (" + values + ") is not shard ID-MIN of COUNT; "
                         "submit a contiguous array (sbatch --array=0-N-1) or give --shard I/N");
    }
    return BatchShard{*i - *m, *n};
}

std::optional<BatchShard> shardOfRecordFile(const std::string& fileName)
{
    static const std::regex re(R"(batch\.([0-9]{1,9})-of-([0-9]{1,9})\.jsonl)");
    std::smatch m;
    if (!std::regex_match(fileName, m, re)) return std::nullopt;
    const BatchShard s{std::size_t(std::stoul(m[1])), std::size_t(std::stoul(m[2]))};
    if (s.count == 0 || s.index >= s.count) return std::nullopt;
    return s;
}

} // namespace vdbhair::app
