// The strand formats and their readers other than .vdb (StrandIO.h); the .vdb reader and writer
// are in StrandIO.cc.
#include "StrandIO.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/io/AbcFile.h>
#include <vdbhair/io/BinFile.h>
#include <vdbhair/io/ConvdataFile.h>
#include <vdbhair/io/DataFile.h>
#include <vdbhair/io/FileUtil.h>
#include <vdbhair/io/HairFile.h>
#include <vdbhair/io/ObjFile.h>
#include <vdbhair/io/TfxFile.h>
#include <vdbhair/io/UsdFile.h>

#include <filesystem>

namespace vdbhair {

namespace {
struct FormatEntry { const char* ext; StrandFormat format; const char* name; bool writable; };
constexpr FormatEntry kFormats[] = {
    {".hair", StrandFormat::Hair, "cyHair", true},
    {".data", StrandFormat::Data, "USC-HairSalon", true},
    {".obj", StrandFormat::Obj, "OBJ lines", true},
    {".ply", StrandFormat::Ply, "PLY (hairutil layout)", true},
    {".vdb", StrandFormat::Vdb, "OpenVDB points", true},
    {".usda", StrandFormat::Usda, "USD BasisCurves (text)", true},
    {".usd", StrandFormat::Usda, "USD BasisCurves (text in a .usd)", false},
    {".abc", StrandFormat::Abc, "Alembic Curves (Ogawa)", true},
    {".tfx", StrandFormat::Tfx, "TressFX", false},
    {".bin", StrandFormat::Bin, "CT2Hair", false},
    {".convdata", StrandFormat::Convdata, "HairNet convdata", false},
};
} // namespace

StrandFormat strandFormatFromPath(const std::string& path, bool forWriting)
{
    const std::string ext = fileExtension(path);
    for (const FormatEntry& f : kFormats) {
        if (ext != f.ext) continue;
        if (forWriting && !f.writable) {
            throw ValueError(path + ": " + f.name + " (" + ext +
                             ") is read-only in vdbhair; write .hair, .data, .obj, .ply, .vdb, .usda or .abc");
        }
        return f.format;
    }
    std::string list;
    for (const FormatEntry& f : kFormats) {
        if (forWriting && !f.writable) continue;
        list += (list.empty() ? "" : ", ") + std::string(f.ext);
    }
    throw ValueError(path + ": unknown strand format '" + (ext.empty() ? std::string("(no extension)") : ext) +
                     "'; " + (forWriting ? "writable" : "supported") + " extensions are " + list);
}

bool isWritable(StrandFormat format)
{
    for (const FormatEntry& f : kFormats) if (f.format == format) return f.writable;
    return false;
}

const char* formatName(StrandFormat format)
{
    for (const FormatEntry& f : kFormats) if (f.format == format) return f.name;
    return "unknown";
}

bool isStrandFile(const std::string& path)
{
    const std::string ext = fileExtension(path);
    for (const FormatEntry& f : kFormats) if (ext == f.ext) return true;
    return false;
}

StrandFormat strandFileFormat(const std::string& path)
{
    // What the path is comes before what its extension says (a folder has none); a missing
    // file is left to the reader, whose message names it.
    std::error_code ec;
    if (std::filesystem::exists(path, ec)) requireRegularFile(path, path);
    return strandFormatFromPath(path);
}

StrandSet readNonVdbStrands(const std::string& path, const ReadOptions& opts, ReadReport* report)
{
    switch (strandFileFormat(path)) {
    case StrandFormat::Hair: return readHair(path, opts, report);
    case StrandFormat::Data: return readData(path, opts, report);
    case StrandFormat::Obj: return readObj(path, opts, report);
    case StrandFormat::Ply: return readPly(path, opts, report);
    case StrandFormat::Vdb: break;
    case StrandFormat::Usda: return readUsda(path, opts, report);
    case StrandFormat::Abc: return readAbc(path, opts, report);
    case StrandFormat::Tfx: return readTfx(path, opts, report);
    case StrandFormat::Bin: return readBin(path, opts, report);
    case StrandFormat::Convdata: return readConvdata(path, opts, report);
    }
    throw ValueError(path + ": an OpenVDB file; readStrands() reads its strands");
}

} // namespace vdbhair
