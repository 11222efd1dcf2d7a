/// @file NpyFile.h
/// @brief NumPy's .npy format (version 1.0) for float32 arrays: what `numpy.load` reads directly.
///
/// The format (numpy.lib.format): the magic `\x93NUMPY`, the version bytes 1 and 0, a
/// little-endian uint16 header length, then an ASCII Python dict literal
/// `{'descr': '<f4', 'fortran_order': False, 'shape': (D, H, W, 4), }` padded with spaces and
/// ended by a newline so that the data starts at a multiple of 64 bytes, then the raw values in C
/// order (the last axis varying fastest).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace vdbhair {

/// @brief The .npy header (magic, version, length, dict, padding) of a little-endian float32
/// C-order array of shape @a shape.
std::string npyHeader(const std::vector<std::size_t>& shape);

/// @brief Write @a data, a float32 array of shape @a shape in C order, to @a path as .npy,
/// atomically (a temporary file renamed into place; FileUtil.h).
/// @param data #(product of shape) floats
/// @throw ValueError if @a shape is empty; IoError if the file cannot be written.
void writeNpy(const std::string& path, const std::vector<std::size_t>& shape, const float* data);

} // namespace vdbhair
