/// @file HairFile.h
/// @brief Cem Yuksel's cyHair binary format (`.hair`).
///
/// Layout (little-endian): a 128-byte header — "HAIR", u32 strand count, u32 point count,
/// u32 array bits (1 segments, 2 points, 4 thickness, 8 transparency, 16 colours), u32 default
/// segments, f32 default thickness, f32 default transparency, f32[3] default colour, char[88]
/// info — then, for each bit set and in that order: u16 segments[strands] (points per strand =
/// segments + 1; without the array every strand has default segments + 1 points),
/// f32 points[3 x points], f32 thickness[points], f32 transparency[points], f32 colours[3 x points].
#pragma once

#include <vdbhair/io/ReadOptions.h>
#include <vdbhair/strands/StrandSet.h>

#include <string>

namespace vdbhair {

/// @brief Read a cyHair file. Absent arrays take the header's defaults (StrandSet::defaults).
/// @throw IoError, FormatError (bad magic, a size the header does not explain, a segment count
/// that disagrees with the point count, a non-finite coordinate).
StrandSet readHair(const std::string& path, const ReadOptions& opts = {}, ReadReport* report = nullptr);

/// @brief Write a cyHair file with every array the set has (segments are omitted when every
/// strand has the same count). Strands of more than 65536 points cannot be written.
/// @throw ValueError, IoError.
void writeHair(const std::string& path, const StrandSet& strands);

} // namespace vdbhair
