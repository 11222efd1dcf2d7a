/// @file VdbPrescan.h
/// @brief Every byte of a `.vdb` that OpenVDB 10 will read, bounded before it reads it: a walk of
/// the file as `io::File::open(delayLoad=false)` and `readGrid()` read it (format 222-224), over a
/// read-only mapping, checking every count, string length and chunk size the file declares
/// against the bytes that remain and against the destination the tree's topology implies (a
/// blosc chunk at most the destination plus 16 bytes, zip at most the destination, an
/// uncompressed chunk exactly the destination: Debian's OpenVDB 10.0.1 writes a negative chunk
/// size of any length into a leaf's buffer). Research and measurements: docs/research/vdb_prescan.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace vdbhair {

/// @brief What the walk found (for reports and tests).
struct VdbPrescanStats
{
    std::uint64_t leaves = 0, chunks = 0, arrays = 0, pages = 0;
    std::uint64_t declaredBytes = 0;  ///< the destination bytes OpenVDB will allocate for what it reads
};

/// @brief A size field the walk checked: its kind ("chunk64blosc", "chunk64zip", "arraybytes",
/// "page32", "strlen", "metacount", ...), its byte offset and the destination it bounds (0 when
/// it bounds a count): what mutation tests and fuzz seeds aim at.
struct VdbPrescanField
{
    std::string kind;
    std::uint64_t offset = 0, destination = 0;
};

/// @brief Walk @a path (see above).
/// @param fields optional: every size field checked, in file order
/// @return false when the file's format is older than 222, which the walk does not cover (the
/// caller's other checks apply); true when every byte is bounded.
/// @throw FormatError naming @a where, the byte offset and the rule broken; IoError.
bool prescanVdbFile(const std::string& path, const std::string& where, VdbPrescanStats* stats = nullptr,
                    std::vector<VdbPrescanField>* fields = nullptr);

} // namespace vdbhair
