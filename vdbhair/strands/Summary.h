/// @file Summary.h
/// @brief summarizeStrands() from per-strand figures, for a reader that summarizes a file without
/// holding its strands (summarizeData(), DataFile.h): the same sums in the same order, so both
/// give the same summary.
#pragma once

#include <vdbhair/strands/Measures.h>

#include <cstdint>
#include <vector>

namespace vdbhair {

/// @brief The summary of #lengths strands of @a vertexCounts vertices and lengths @a lengths (as
/// strandLengths() gives them), whose @a vertices vertices lie in @a bbox.
StrandSummary summarizeStrands(std::size_t vertices, const BBox& bbox, const std::vector<float>& lengths,
                               const std::vector<std::uint32_t>& vertexCounts);

} // namespace vdbhair
