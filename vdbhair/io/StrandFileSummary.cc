#include "StrandFileSummary.h"

#include <vdbhair/io/DataFile.h>
#include <vdbhair/io/FileUtil.h>
#include <vdbhair/io/StrandIO.h>

#include <filesystem>
#include <system_error>

namespace vdbhair {

StrandSummary summarizeStrandFile(const std::string& path, const ReadOptions& opts, ReadReport* report)
{
    // As readStrands(): what the path is comes before what its extension says.
    std::error_code ec;
    if (std::filesystem::exists(path, ec)) requireRegularFile(path, path);
    if (strandFormatFromPath(path) != StrandFormat::Data) return summarizeStrands(readStrands(path, opts, report));
    return summarizeData(path, opts, report);
}

} // namespace vdbhair
