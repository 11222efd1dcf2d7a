#include "VdbFile.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/io/FileUtil.h>

#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <new>
#include <stdexcept>

namespace vdbhair {

void initializeOpenVdb()
{
    static std::once_flag once;
    std::call_once(once, [] { openvdb::initialize(); });
}

namespace {

/// Reads a .vdb file's plain values at known offsets, every size checked against the file size
/// before it is used (nothing is allocated from the file).
class LayoutReader
{
public:
    LayoutReader(const std::string& path, const std::string& where) : mIn(path, std::ios::binary), mWhere(where)
    {
        if (!mIn) throw IoError(where + ": cannot open for reading: " + std::strerror(errno));
        mIn.seekg(0, std::ios::end);
        mSize = std::uint64_t(std::max<std::streamoff>(0, mIn.tellg()));
        mIn.seekg(0);
    }
    std::uint64_t size() const { return mSize; }
    std::uint64_t offset() const { return mOffset; }
    [[noreturn]] void fail(std::uint64_t at, const std::string& msg) const
    {
        throw FormatError(mWhere + ": at byte " + std::to_string(at) + ": " + msg);
    }
    void seek(std::uint64_t off)
    {
        mOffset = off;
        mIn.clear();
        mIn.seekg(std::streamoff(off));
    }
    /// @brief Fail unless @a bytes remain before @a limit (the file size or a grid's data block).
    void require(std::uint64_t bytes, std::uint64_t limit, const std::string& what) const
    {
        if (mOffset > limit || bytes > limit - mOffset) {
            fail(mOffset, what + " needs " + std::to_string(bytes) + " bytes but only " +
                              std::to_string(mOffset > limit ? 0 : limit - mOffset) + " remain" +
                              (limit == mSize ? " in the file" : " before the grid's data"));
        }
    }
    template<typename T>
    T read(std::uint64_t limit, const char* what)
    {
        require(sizeof(T), limit, what);
        T v{};
        mIn.read(reinterpret_cast<char*>(&v), sizeof(T));
        if (!mIn) fail(mOffset, std::string("cannot read ") + what);
        mOffset += sizeof(T);
        return v;
    }
    void skip(std::uint64_t bytes, std::uint64_t limit, const std::string& what)
    {
        require(bytes, limit, what);
        seek(mOffset + bytes);
    }
    /// An OpenVDB string (uint32 length, then the bytes); its first 256 characters are returned.
    std::string string(std::uint64_t limit, const char* what)
    {
        const std::uint64_t at = mOffset;
        const std::uint32_t n = read<std::uint32_t>(limit, what);
        require(n, limit, std::string(what) + " of " + std::to_string(n) + " characters (declared at byte " + std::to_string(at) + ")");
        std::string s(std::min<std::uint32_t>(n, 256u), '\0');
        mIn.read(s.data(), std::streamsize(s.size()));
        seek(mOffset + n);
        return s;
    }
    /// A MetaMap (uint32 count; name, type name, uint32 value size and value each) within @a limit.
    void metadata(std::uint64_t limit, const std::string& what)
    {
        const std::uint64_t at = mOffset;
        const std::uint32_t count = read<std::uint32_t>(limit, "metadata count");
        // Each entry needs at least 12 bytes: two empty strings and a value size.
        if (count > (limit - mOffset) / 12) {
            fail(at, what + " declares " + std::to_string(count) + " entries but only " + std::to_string(limit - mOffset) +
                         " bytes remain for them (at least 12 each)");
        }
        for (std::uint32_t i = 0; i < count; ++i) {
            string(limit, "a metadata name");
            string(limit, "a metadata type name");
            const std::uint64_t sizeAt = mOffset;
            const std::uint32_t bytes = read<std::uint32_t>(limit, "a metadata value size");
            if (bytes > limit - mOffset) {
                fail(sizeAt, what + " entry " + std::to_string(i) + " declares a value of " + std::to_string(bytes) +
                                 " bytes but only " + std::to_string(limit - mOffset) + " remain");
            }
            seek(mOffset + bytes);
        }
    }

private:
    std::ifstream mIn;
    std::string mWhere;
    std::uint64_t mSize = 0, mOffset = 0;
};

} // namespace

void checkVdbFileLayout(const std::string& path, const std::string& where)
{
    LayoutReader in(path, where);
    const std::uint64_t end = in.size();
    // Header (io::Archive::readHeader): magic, format version, library version, whether grids
    // have offsets, (before format 222) one compression flag, then a 36-character UUID.
    if (end < 8 || in.read<std::int64_t>(end, "the magic number") != std::int64_t(openvdb::OPENVDB_MAGIC)) {
        throw FormatError(where + ": not a readable VDB file (the first 8 bytes are not OpenVDB's magic number)");
    }
    const std::uint32_t version = in.read<std::uint32_t>(end, "the file format version");
    if (version > openvdb::OPENVDB_FILE_VERSION) {
        in.fail(8, "format version " + std::to_string(version) + " is newer than the " +
                       std::to_string(openvdb::OPENVDB_FILE_VERSION) + " this OpenVDB reads");
    }
    if (version < openvdb::OPENVDB_FILE_VERSION_NODE_MASK_COMPRESSION) return;  // see the header
    in.skip(8, end, "the library version");
    const char hasOffsets = in.read<char>(end, "the grid offsets flag");
    in.skip(36, end, "the UUID");
    in.metadata(end, "the file's metadata");
    if (!hasOffsets) return;  // grids follow one another without descriptors' offsets

    // Grid descriptors (io::GridDescriptor::read): name, type, instance parent, then the grid's
    // start, data block start and end; the next descriptor starts at the grid's end.
    const std::uint64_t countAt = in.offset();
    const std::uint32_t count = in.read<std::uint32_t>(end, "the grid count");
    if (count > (end - in.offset()) / 36) {
        in.fail(countAt, "the file declares " + std::to_string(std::int32_t(count)) + " grids but only " +
                             std::to_string(end - in.offset()) + " bytes remain (a grid descriptor alone needs 36)");
    }
    for (std::uint32_t g = 0; g < count; ++g) {
        const std::uint64_t descAt = in.offset();
        const std::string name = in.string(end, "a grid name");
        in.string(end, "a grid type name");
        in.string(end, "a grid's instance parent name");
        const std::int64_t gridPos = in.read<std::int64_t>(end, "a grid start offset");
        const std::int64_t blockPos = in.read<std::int64_t>(end, "a grid data offset");
        const std::int64_t endPos = in.read<std::int64_t>(end, "a grid end offset");
        if (!(std::int64_t(in.offset()) <= gridPos && gridPos <= blockPos && blockPos <= endPos && std::uint64_t(endPos) <= end)) {
            in.fail(descAt, "grid " + std::to_string(g) + " ('" + name + "') has start " + std::to_string(gridPos) + ", data " +
                                std::to_string(blockPos) + " and end " + std::to_string(endPos) + "; they must satisfy " +
                                std::to_string(in.offset()) + " <= start <= data <= end <= " + std::to_string(end) + " (the file size)");
        }
        // The grid's compression flags and metadata come before its data block.
        in.seek(std::uint64_t(gridPos));
        in.read<std::uint32_t>(std::uint64_t(blockPos), "the grid's compression flags");
        in.metadata(std::uint64_t(blockPos), "grid '" + name + "' metadata");
        in.seek(std::uint64_t(endPos));
    }
}

namespace {

/// What is said when OpenVDB's tree reader asks for more memory than there is: the sizes inside
/// a grid's tree (compressed buffers, attribute arrays) are the part checkVdbFileLayout() cannot
/// check, and OpenVDB allocates what they declare before it could find them wrong.
const char* const kTreeSizes =
    "the grid's tree declares a buffer larger than memory allows (OpenVDB allocates the sizes inside a grid's "
    "tree as the file states them; the file is damaged or not what it claims)";

/// Open @a path, turning OpenVDB's errors into ours.
void openFile(openvdb::io::File& file, const std::string& path, const std::string& where)
{
    requireRegularFile(path, where);
    checkVdbFileLayout(path, where);
    try {

        file.open(/*delayLoad=*/false);
    } catch (const openvdb::Exception& e) {
        throw FormatError(where + ": not a readable VDB file (" + std::string(e.what()) + ")");
    }
}

std::string listNames(const std::vector<std::string>& names)
{
    if (names.empty()) return "the file has no grids";
    std::string s = "the file has ";
    for (std::size_t i = 0; i < names.size(); ++i) s += (i ? ", '" : "'") + names[i] + "'";
    return s;
}

} // namespace

openvdb::GridPtrVec readVdbGrids(const std::string& path, const std::string& where)
{
    initializeOpenVdb();
    openvdb::io::File file(path);
    openFile(file, path, where);
    try {
        openvdb::GridPtrVecPtr grids = file.getGrids();
        file.close();
        return grids ? *grids : openvdb::GridPtrVec{};
    } catch (const openvdb::Exception& e) {
        throw FormatError(where + ": cannot read the grids (" + std::string(e.what()) + ")");
    } catch (const std::bad_alloc&) {
        throw FormatError(where + ": " + kTreeSizes);
    } catch (const std::length_error&) {
        throw FormatError(where + ": " + kTreeSizes);
    }
}

std::vector<std::string> vdbGridNames(const std::string& path, const std::string& where)
{
    initializeOpenVdb();
    openvdb::io::File file(path);
    openFile(file, path, where);
    std::vector<std::string> names;
    for (auto it = file.beginName(); it != file.endName(); ++it) names.push_back(it.gridName());
    file.close();
    return names;
}

openvdb::GridBase::Ptr readVdbGrid(const std::string& path, const std::string& name,
                                   const std::string& where)
{
    initializeOpenVdb();
    openvdb::io::File file(path);
    openFile(file, path, where);
    std::vector<std::string> names;
    for (auto it = file.beginName(); it != file.endName(); ++it) names.push_back(it.gridName());
    if (!file.hasGrid(name)) {
        file.close();
        throw LookupError(where + ": no grid named '" + name + "'; " + listNames(names));
    }
    try {
        openvdb::GridBase::Ptr grid = file.readGrid(name);
        file.close();
        return grid;
    } catch (const openvdb::Exception& e) {
        throw FormatError(where + ": cannot read grid '" + name + "' (" + std::string(e.what()) + ")");
    } catch (const std::bad_alloc&) {
        throw FormatError(where + ": grid '" + name + "': " + kTreeSizes);
    } catch (const std::length_error&) {
        throw FormatError(where + ": grid '" + name + "': " + kTreeSizes);
    }
}

void writeVdbGrids(const std::string& path, const openvdb::GridCPtrVec& grids, const std::string& where)
{
    initializeOpenVdb();
    AtomicOutput out(path);
    try {
        openvdb::io::File file(out.tempPath());
        file.write(grids);
        file.close();
    } catch (const openvdb::Exception& e) {
        throw IoError(where + ": cannot write (" + std::string(e.what()) + ")");
    }
    out.commit();
}

} // namespace vdbhair
