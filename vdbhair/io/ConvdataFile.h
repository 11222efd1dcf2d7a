/// @file ConvdataFile.h
/// @brief HairNet's `.convdata` (Zhou et al. 2018 data generation): a NumPy `.npy` array of
/// little-endian float32, shape (4·P, H, W), read as (P, 4, H, W): v[i, 0:3, n, m] is point i
/// (root first) of the strand in grid slot (n, m) and v[i, 3, n, m] a curvature value that
/// vdbhair ignores. Slots whose points are all exactly zero are empty and are skipped (reported).
/// Read only.
#pragma once

#include <vdbhair/io/ReadOptions.h>
#include <vdbhair/strands/StrandSet.h>

#include <string>

namespace vdbhair {

/// @throw IoError, FormatError, UnsupportedError (another dtype, Fortran order, another rank).
StrandSet readConvdata(const std::string& path, const ReadOptions& opts = {}, ReadReport* report = nullptr);

} // namespace vdbhair
