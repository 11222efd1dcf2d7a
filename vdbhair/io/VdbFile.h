/// @file VdbFile.h
/// @brief Reading and writing `.vdb` files with vdbhair's error conventions: OpenVDB's
/// exceptions become typed vdbhair errors naming the file, and writes are atomic.
#pragma once

#include <openvdb/Grid.h>

#include <string>
#include <vector>

namespace vdbhair {

/// @brief openvdb::initialize(), once (thread-safe, cheap after the first call).
void initializeOpenVdb();

/// @brief Every grid of @a path, fully loaded.
/// @param where message prefix, e.g. "info(a.vdb)"
/// @throw IoError (cannot open), FormatError (not a valid VDB file).
openvdb::GridPtrVec readVdbGrids(const std::string& path, const std::string& where);

/// @brief The grid named @a name of @a path.
/// @throw LookupError listing the grids the file does have.
openvdb::GridBase::Ptr readVdbGrid(const std::string& path, const std::string& name,
                                   const std::string& where);

/// @brief Names of the grids in @a path, in file order (without loading their trees).
std::vector<std::string> vdbGridNames(const std::string& path, const std::string& where);

/// @brief Write @a grids to @a path through a temporary file renamed into place.
/// @throw IoError.
void writeVdbGrids(const std::string& path, const openvdb::GridCPtrVec& grids, const std::string& where);

} // namespace vdbhair
