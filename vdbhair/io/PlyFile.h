/// @file PlyFile.h
/// @brief Strands in PLY, in the layout of hairutil (kenshi84/hairutil): an element `vertex`
/// (float x, y, z; optional uchar red, green, blue), an element `strand` (integer `nsegs`:
/// strand i has nsegs + 1 consecutive vertices) and an optional element `edge` (int vertex1,
/// vertex2), redundant with nsegs. ASCII and binary little-endian, read and write.
///
/// Reading accepts any numeric type for these properties, skips other elements and properties
/// (list properties included) and checks that the strands' vertex counts add up to the vertex
/// count. Writing emits the edge element too, so that hairutil reads the result.
///
/// Two more layouts are read, without a `strand` element:
/// - **Line sets** (Open3D's LineSet, trimesh): `vertex` and `edge` (`vertex1`, `vertex2`, 0-based).
///   The edges are chained into strands by EdgeChains.h, as the OBJ reader chains `l` elements
///   (any order and direction; rooted at the lower-index end or ReadOptions::objRootNear; a
///   branch or a loop is an error naming the vertex and the edges). Vertices on no edge are
///   ignored with a warning.
/// - **Points in runs** (NeuralHaircut, GaussianHaircut: 100 points a strand): only `vertex`;
///   each run of ReadOptions::pointsPerStrand consecutive vertices is one strand, root first.
///   Without that option such a file is an error that says to set it; a vertex count that is not
///   a multiple of it is an error naming both numbers.
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
