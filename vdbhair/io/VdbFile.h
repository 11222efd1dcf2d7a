/// @file VdbFile.h
/// @brief Reading and writing `.vdb` files with vdbhair's error conventions: OpenVDB's
/// exceptions become typed vdbhair errors naming the file, and writes are atomic.
#pragma once

#include <openvdb/Grid.h>

#include <functional>
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
/// Checked, against the file size and without allocating by any size read, value by value as
/// OpenVDB 10 reads them for the file's format version (from the three-number versions before
/// 211 on): the magic number and version; the UUID (36 characters from format 218, which OpenVDB
/// parses as text: anything else fails its stream and makes its next string length an
/// uninitialized value); the file-level metadata (every name, type name and value within the
/// bytes that remain; fixed-size types such as `int64` must declare their own size, since OpenVDB
/// reads that size whatever is declared; a grid's delayed-load metadata with its leaf count
/// within the grid's bytes and its Blosc headers' sizes matching it); the grid count (each
/// descriptor needs at least 36 bytes, 32 before format 216); each grid descriptor's names and
/// its offsets (descriptor end <= grid start <= data block start <= grid end <= file size); and
/// each grid's compression flags, metadata and transform type name within the grid's bytes before
/// its data block. A file written without grid offsets (io::Stream) holds its grids one after
/// another: there the first grid's descriptor and head are checked, and no more.
///
/// Not checked (OpenVDB's tree reader would have to be reimplemented): the transform's map, the
/// tree topology (root table, node masks) and the leaf buffers, including points attribute arrays
/// and their compressed sizes (io::bloscFromStream allocates what the stream declares); the heads
/// of the second and later grids of a file without offsets; and, before format 216, the
/// transform (it follows the tree there).
/// @throw IoError if the file cannot be read; FormatError naming the byte and the rule.
void checkVdbFileLayout(const std::string& path, const std::string& where);

/// @brief Run @a read under the allocation budget of reading @a path: readBudgetBytes() of its size
/// (Memory.h), the second line behind the pre-scan. A request past it, or one memory cannot meet,
/// is one LimitError or FormatError naming @a where. The readers below run in it; a reader that
/// goes on to expand what OpenVDB read (strands from a points grid, whose uniform arrays hold any
/// number of points in one value) runs the expansion in it too. Within it, the readers below
/// reading the same @a path add no budget of their own.
void withinReadBudget(const std::string& path, const std::string& where, const std::function<void()>& read);

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
