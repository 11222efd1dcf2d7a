/// @file BatchShard.h
/// @brief Which share of a batch's inputs one process runs (`--shard I/N`, or a Slurm array task):
/// the inputs at sorted positions p with p mod N = I, so N shards cover the set exactly once and
/// the split depends on nothing but the input list.
#pragma once

#include <cstddef>
#include <optional>
#include <string>

namespace vdbhair::app {

struct BatchShard
{
    std::size_t index = 0;  ///< I, from 0
    std::size_t count = 1;  ///< N; 1: the whole set

    bool sharded() const { return count > 1; }
    /// Whether the input at sorted position @a position is this shard's.
    bool holds(std::size_t position) const { return position % count == index; }
    /// The shard's record file in the output folder: batch.jsonl unsharded, else batch.<I>-of-<N>.jsonl.
    std::string recordFileName() const;
};

/// @brief Parse `I/N` (0 <= I < N).
/// @throw ValueError naming the option, the value and the rule.
BatchShard parseShard(const std::string& text);

/// @brief The shard of a Slurm array task: SLURM_ARRAY_TASK_ID minus SLURM_ARRAY_TASK_MIN (0 when
/// unset) of SLURM_ARRAY_TASK_COUNT; nothing outside an array job.
/// @throw ValueError when the variables are set but do not make a shard (a task id out of range, a
/// count missing), naming them and their values.
std::optional<BatchShard> shardFromSlurm();

/// @brief Parse a record file name written by BatchShard::recordFileName() of a sharded run.
std::optional<BatchShard> shardOfRecordFile(const std::string& fileName);

} // namespace vdbhair::app
