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
/// @brief Check what can be checked of a .vdb file's layout before OpenVDB reads it, since
/// OpenVDB trusts the sizes in the file and allocates what they declare (a flipped bit can ask
/// for terabytes before any error).
///
/// Checked, against the file size and without allocating by any size read: the magic number;
/// the file-level metadata (every name, type name and value size within the bytes that remain);
/// the grid count (each descriptor needs at least 36 bytes); each grid descriptor's names and its
/// offsets (descriptor end <= grid start <= data block start <= grid end <= file size); and each
/// grid's compression flags and metadata within the grid's bytes before its data block.
///
/// Not checked (OpenVDB's tree reader would have to be reimplemented): the transform, the tree
/// topology (root table, node masks) and the leaf buffers, including points attribute arrays and
/// their compressed sizes (io::bloscFromStream allocates what the stream declares). Files older
/// than format 222 (OpenVDB 3) get only the magic and header checks.
/// @throw IoError if the file cannot be read; FormatError naming the byte and the rule.
void checkVdbFileLayout(const std::string& path, const std::string& where);

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
