/// @file StrandIO.h
/// @brief Reading and writing strands in any supported format, chosen by extension (and checked
/// by magic where the format has one).
///
/// | extension | format | read | write |
/// |---|---|---|---|
/// | .hair | cyHair (HairFile.h) | yes | yes |
/// | .data | USC-HairSalon (DataFile.h) | yes | yes |
/// | .obj | OBJ lines: two-vertex edges written, edges in any order read (ObjFile.h) | yes | yes |
/// | .ply | hairutil PLY, ascii / binary LE (PlyFile.h) | yes | yes |
/// | .vdb | OpenVDB points grid `strands` (VdbStrands.h) | yes | yes |
/// | .usda | USD BasisCurves, text (UsdFile.h) | yes | yes |
/// | .abc | Alembic Curves, Ogawa (AbcFile.h) | yes | yes |
/// | .tfx | TressFX binary 3/4, ASCII 1/2 (TfxFile.h) | yes | no |
/// | .bin | CT2Hair (BinFile.h) | yes | no |
/// | .convdata | HairNet (ConvdataFile.h) | yes | no |
#pragma once

#include <vdbhair/io/ObjFile.h>
#include <vdbhair/io/PlyFile.h>
#include <vdbhair/io/UsdFile.h>
#include <vdbhair/io/ReadOptions.h>
#include <vdbhair/io/VdbStrands.h>
#include <vdbhair/strands/StrandSet.h>

#include <string>

namespace vdbhair {

enum class StrandFormat { Hair, Data, Obj, Ply, Vdb, Usda, Abc, Tfx, Bin, Convdata };

/// @brief The format of @a path from its extension.
/// @param forWriting also require a writable format
/// @throw ValueError naming the extension and the supported ones.
StrandFormat strandFormatFromPath(const std::string& path, bool forWriting = false);

bool isWritable(StrandFormat format);
const char* formatName(StrandFormat format);

/// @brief Whether @a path has an extension vdbhair reads as strands.
bool isStrandFile(const std::string& path);

/// @brief The format of the strand file @a path (strandFormatFromPath()), after checking that a
/// path that exists is a regular file (a folder has no extension to go by).
/// @throw ValueError (unknown extension), IoError (not a regular file).
StrandFormat strandFileFormat(const std::string& path);

/// @brief Read strands from any supported file.
StrandSet readStrands(const std::string& path, const ReadOptions& opts = {}, ReadReport* report = nullptr);

/// @brief Read strands from a file of any supported format but .vdb (StrandFormats.cc).
/// @throw ValueError for a .vdb file; what readStrands() throws otherwise.
StrandSet readNonVdbStrands(const std::string& path, const ReadOptions& opts = {}, ReadReport* report = nullptr);

struct WriteOptions
{
    PlyEncoding plyEncoding = PlyEncoding::Binary;
    ObjLineStyle objLines = ObjLineStyle::Edges;
    VdbPointsOptions vdb;
    UsdWriteOptions usd;
};

/// @brief Write strands in the format of @a path's extension, atomically.
/// @throw ValueError (unwritable format, empty set where the format needs strands), IoError.
void writeStrands(const std::string& path, const StrandSet& strands, const WriteOptions& opts = {});

} // namespace vdbhair
