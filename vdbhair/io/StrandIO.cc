#include "StrandIO.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/io/AbcFile.h>
#include <vdbhair/io/DataFile.h>
#include <vdbhair/io/FileUtil.h>
#include <vdbhair/io/HairFile.h>
#include <vdbhair/io/ObjFile.h>

namespace vdbhair {

namespace {
StrandSet readAnyStrands(const std::string& path, const ReadOptions& opts, ReadReport* report)
{
    if (fileExtension(path) != ".vdb") return readNonVdbStrands(path, opts, report);  // checks the path itself
    strandFileFormat(path);  // a folder named .vdb: the same message as any other format's
    return readVdbStrands(path, opts, report, opts.vdbGrid);
}
} // namespace

StrandSet readStrands(const std::string& path, const ReadOptions& opts, ReadReport* report)
{
    checkReadOptions(opts);
    StrandSet strands = readAnyStrands(path, opts, report);
    // The one place ReadOptions::roots is applied, whichever reader ran (RootEnd.h).
    const RootEndDecision d = orientStrandRoots(strands, opts.roots, opts.rootsHeadDistance);
    const std::string line =
        opts.roots == RootEnd::Auto ? describeRootEndDecision(d, spelled(readOptionSetting(opts.rootsName), opts.spelling) + "auto") : std::string();
    if (report && !line.empty()) report->warnings.push_back(path + ": " + line);
    return strands;
}

void writeStrands(const std::string& path, const StrandSet& strands, const WriteOptions& opts)
{
    switch (strandFormatFromPath(path, /*forWriting=*/true)) {
    case StrandFormat::Hair: writeHair(path, strands); return;
    case StrandFormat::Data: writeData(path, strands); return;
    case StrandFormat::Obj: writeObj(path, strands, opts.objLines); return;
    case StrandFormat::Ply: writePly(path, strands, opts.plyEncoding); return;
    case StrandFormat::Vdb: writeVdbStrands(path, strands, opts.vdb); return;
    case StrandFormat::Usda: writeUsda(path, strands, opts.usd); return;
    case StrandFormat::Abc: writeAbc(path, strands); return;
    default: break;
    }
    throw ValueError(path + ": format is not writable");
}

} // namespace vdbhair
