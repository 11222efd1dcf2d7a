/// @file PlyFile.h
/// @brief Strands in PLY, in the layout of hairutil (kenshi84/hairutil): an element `vertex`
/// (float x, y, z; optional uchar red, green, blue), an element `strand` (integer `nsegs`:
/// strand i has nsegs + 1 consecutive vertices) and an optional element `edge` (int vertex1,
/// vertex2), redundant with nsegs. ASCII and binary little-endian, read and write.
///
/// Reading accepts any numeric type for these properties, skips other elements and properties
/// (list properties included) and checks that the strands' vertex counts add up to the vertex
/// count. Writing emits the edge element too, so that hairutil reads the result.
#pragma once

#include <vdbhair/io/ReadOptions.h>
#include <vdbhair/strands/StrandSet.h>

#include <string>

namespace vdbhair {

enum class PlyEncoding { Binary, Ascii };

/// @throw IoError, FormatError, UnsupportedError (big-endian data).
StrandSet readPly(const std::string& path, const ReadOptions& opts = {}, ReadReport* report = nullptr);

/// @brief Write positions, and colours (as uchar) when present.
void writePly(const std::string& path, const StrandSet& strands, PlyEncoding encoding = PlyEncoding::Binary);

} // namespace vdbhair
