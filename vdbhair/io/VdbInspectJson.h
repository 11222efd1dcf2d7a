/// @file VdbInspectJson.h
/// @brief What `info --json` and `inspect --json` print of a .vdb file's grids, and what Python's
/// inspect() returns: one record of a grid whichever front end asked (as FieldJson.h is field's).
#pragma once

#include <vdbhair/io/VdbInfo.h>
#include <vdbhair/io/VdbInspect.h>

#include <nlohmann/json.hpp>

namespace vdbhair {

/// @brief A grid's description (describeVdbFile()): name, type, value_type, class, vector_type
/// (null when none), voxel_size (one number when uniform, else x, y, z), active_voxels,
/// active_tiles, leaf_nodes, memory_bytes, bbox (null when empty), metadata, and for a points
/// grid "points" (count, attributes, groups). `info --json`'s record of a grid.
nlohmann::json gridInfoJson(const GridInfo& g);

/// @brief A grid's report (inspectVdbFile()): gridInfoJson() and index_bbox, tiles_by_level,
/// internal_nodes, leaf_fill, the value statistics (length for vectors, values for scalars,
/// points_per_voxel for points) and explanation. `inspect --json`'s record of a grid, and each
/// dict of Python's inspect().
nlohmann::json gridReportJson(const GridReport& r);

} // namespace vdbhair
