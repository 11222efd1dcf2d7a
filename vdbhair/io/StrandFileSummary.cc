#include "StrandFileSummary.h"

#include <vdbhair/io/DataFile.h>
#include <vdbhair/io/StrandIO.h>

namespace vdbhair {

StrandSummary summarizeStrandFile(const std::string& path, const ReadOptions& opts, ReadReport* report)
{
    if (strandFileFormat(path) != StrandFormat::Data) return summarizeStrands(readNonVdbStrands(path, opts, report));
    return summarizeData(path, opts, report);
}

} // namespace vdbhair
