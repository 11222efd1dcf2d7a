/// @file VdbInspect.h
/// @brief A closer look at a `.vdb` file than `info`: per grid, the value statistics (for vector
/// grids the distribution of lengths and the share of unit vectors), active voxels and tiles by
/// tree level, memory, index and world bounding boxes, how full the leaves are, and the vdbhair
/// metadata explained in words (how the grid was made). Used by `vdbhair inspect`.
///
/// Statistics count every active value once per voxel it covers (a tile of 8³ counts 512 times),
/// as OpenVDB's own `tools::statistics` does. Sums run in double, serially in tree order, so they
/// do not depend on the thread count. Quantiles come from a 4096-bin histogram between the
/// minimum and the maximum, interpolated between the least and the greatest value a bin saw:
/// within 1/4096 of the range, and exact for discrete values.
#pragma once

#include <vdbhair/io/VdbInfo.h>

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace vdbhair {

/// Statistics of scalar values, or of vector lengths.
struct ValueStats
{
    std::uint64_t count = 0;  ///< active values, tiles counted once per voxel
    double min = 0.0, max = 0.0, mean = 0.0, stddev = 0.0;
    double p01 = 0.0, p50 = 0.0, p99 = 0.0;  ///< 1st, 50th and 99th percentiles
};

struct GridReport
{
    GridInfo info;
    bool isVector = false, isScalar = false;
    ValueStats values;            ///< scalars: the values; vectors: their lengths; points: points per active voxel
    double unitShare = 0.0;       ///< vectors: share of lengths within 1e-3 of 1
    double zeroShare = 0.0;       ///< vectors: share of zero vectors; scalars: share of zeros
    Vec3d meanVector{0.0};        ///< vectors: the mean vector
    double coherence = 0.0;       ///< vectors: length of the mean unit direction (1: all parallel, ~0: all directions)
    std::array<std::uint64_t, 3> tilesByLevel{{0, 0, 0}};  ///< active tiles: root children (4096³), upper (128³), lower (8³) nodes
    std::uint64_t internalNodes = 0;
    bool emptyIndexBBox = true;
    std::array<int, 3> indexMin{{0, 0, 0}}, indexMax{{0, 0, 0}};  ///< active voxels' index bounding box (inclusive)
    double leafFillMean = 0.0, leafFillMin = 0.0, leafFillMax = 0.0;  ///< active voxels per leaf over 512
    double leafFullShare = 0.0;   ///< share of leaves with all 512 voxels active
    std::string explanation;      ///< the grid's name and vdbhair metadata in words ("" when there is nothing to say)
};

/// @brief Inspect every grid of @a path, in file order.
/// @throw IoError, FormatError.
std::vector<GridReport> inspectVdbFile(const std::string& path);

/// @brief As inspectVdbFile(path), keeping only the grid named @a grid (every grid when empty):
/// `inspect --grid`, Python's `inspect(grid=)`.
/// @throw LookupError "<path>: no grid named '<grid>' (the file has: <its grids>)", IoError,
/// FormatError.
std::vector<GridReport> inspectVdbFile(const std::string& path, const std::string& grid);

/// @brief The grid's name and metadata in words: what it holds and how vdbhair made it.
std::string explainGrid(const GridInfo& info);

} // namespace vdbhair
