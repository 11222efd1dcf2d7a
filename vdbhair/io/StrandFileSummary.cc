#include "StrandFileSummary.h"

#include <vdbhair/io/DataFile.h>
#include <vdbhair/io/StrandIO.h>

namespace vdbhair {

StrandSummary summarizeStrandFile(const std::string& path, const ReadOptions& opts, ReadReport* report)
{
    checkReadOptions(opts);
    const StrandFormat format = strandFileFormat(path);
    if (format == StrandFormat::Data && opts.roots == RootEnd::First) return summarizeData(path, opts, report);
    if (format == StrandFormat::Vdb) return summarizeStrands(readNonVdbStrands(path, opts, report));  // throws ValueError
    // readStrands() applies ReadOptions::roots (the .data scan reads the strands as stored).
    return summarizeStrands(readStrands(path, opts, report));
}

} // namespace vdbhair
