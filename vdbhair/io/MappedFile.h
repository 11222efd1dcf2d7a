/// @file MappedFile.h
/// @brief A whole file's bytes, read-only, without copying them: the binary readers' input.
#pragma once

#include <openvdb/util/NullInterrupter.h>

#include <cstddef>
#include <string>
#include <vector>

namespace vdbhair {

/// @brief The bytes of a regular file, mapped read-only into memory (mmap with the pages loaded
/// up front), or read into a buffer where a file cannot be mapped. The readers then copy each
/// value once, from the file's pages to the StrandSet: reading a 77 MB file into a fresh buffer
/// first cost more than all the parsing (zeroing and faulting in the buffer, then copying).
/// @warning A file truncated by another process while it is mapped ends the process with SIGBUS
/// when a page past the new end is read (the price of not copying; files being rewritten in place
/// are not read safely by any reader, but a copy would fail with an error instead).
class MappedFile
{
public:
    /// @param where prefix of error messages, e.g. "readHair(a.hair)"
    /// @param interrupter optional progress (the stage "reading NAME", in bytes) and Ctrl-C
    /// @throw IoError if the file is not a regular file or cannot be opened or read;
    /// InterruptedError when the interrupter says stop.
    MappedFile(const std::string& path, const std::string& where,
               openvdb::util::NullInterrupter* interrupter = nullptr);
    ~MappedFile();
    MappedFile(const MappedFile&) = delete;
    MappedFile& operator=(const MappedFile&) = delete;

    const char* data() const { return mData; }
    std::size_t size() const { return mSize; }

private:
    const char* mData = nullptr;
    std::size_t mSize = 0;
    void* mMap = nullptr;       ///< the mapping (nullptr: the bytes are in mBuffer)
    std::vector<char> mBuffer;  ///< where mapping was not possible
};

} // namespace vdbhair
