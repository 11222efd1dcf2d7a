/// @file StrandFileSummary.h
/// @brief The summary of a strand file (counts, bounds, ranges of length and vertices per strand:
/// `vdbhair info`), measured where the file lies when its format allows it.
#pragma once

#include <vdbhair/io/ReadOptions.h>
#include <vdbhair/strands/Measures.h>

#include <string>

namespace vdbhair {

/// @brief summarizeStrands(readNonVdbStrands(@a path, @a opts, @a report)), the same figures,
/// warnings and errors; a `.data` file is measured in place (summarizeData(), DataFile.h), any
/// other format is read first. The strands of a `.vdb` file are summarized with summarizeStrands(readStrands()).
/// @throw ValueError for a `.vdb` file.
StrandSummary summarizeStrandFile(const std::string& path, const ReadOptions& opts = {}, ReadReport* report = nullptr);

} // namespace vdbhair
