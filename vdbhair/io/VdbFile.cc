#include "VdbFile.h"
#include "VdbPrescan.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/Memory.h>
#include <vdbhair/io/FileUtil.h>

#include <openvdb/io/DelayedLoadMetadata.h>
#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdint>
#include <limits>
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
/// before it is used (nothing is allocated from the file). It follows OpenVDB 10's readers value
/// by value (io::Archive::readHeader, MetaMap::readMeta, io::GridDescriptor::read,
/// io::DelayedLoadMetadata::readValue, math::Transform::read), format version by format version.
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
    /// @brief The file's UUID as OpenVDB reads it from format 218 on (boost's operator>> for a
    /// uuid): 32 hexadecimal digits with dashes after the 8th, 12th, 16th and 20th, each character
    /// after any white space. Anything else leaves OpenVDB's stream failed, and a failed stream
    /// makes its next string length an uninitialized value (openvdb::readString).
    void uuidText(std::uint64_t limit)
    {
        const std::uint64_t at = mOffset;
        auto next = [&]() {
            char c;
            do {
                c = read<char>(limit, "the UUID");
            } while (c == ' ' || c == '\t' || c == '\n' || c == '\v' || c == '\f' || c == '\r');
            return c;
        };
        for (int i = 0; i < 16; ++i) {
            for (int k = 0; k < 2; ++k) {
                if (!std::isxdigit(static_cast<unsigned char>(next()))) {
                    fail(at, "the UUID is not 32 hexadecimal digits with 4 dashes (8-4-4-4-12)");
                }
            }
            if ((i == 3 || i == 5 || i == 7 || i == 9) && next() != '-') {
                fail(at, "the UUID is not 32 hexadecimal digits with 4 dashes (8-4-4-4-12)");
            }
        }
    }
    /// A MetaMap (uint32 count; name, type name, uint32 value size and value each) within @a limit.
    /// @a treeBytes bounds the leaf count of a grid's delayed-load metadata (each leaf of the tree
    /// takes at least a byte of the file).
    void metadata(std::uint64_t limit, const std::string& what, std::uint64_t treeBytes)
    {
        const std::uint64_t at = mOffset;
        const std::uint32_t count = read<std::uint32_t>(limit, "metadata count");
        // Each entry needs at least 12 bytes: two empty strings and a value size.
        if (count > (limit - mOffset) / 12) {
            fail(at, what + " declares " + std::to_string(count) + " entries but only " + std::to_string(limit - mOffset) +
                         " bytes remain for them (at least 12 each)");
        }
        for (std::uint32_t i = 0; i < count; ++i) {
            const std::string entry = what + " entry " + std::to_string(i);
            string(limit, "a metadata name");
            const std::string type = string(limit, "a metadata type name");
            const std::uint64_t sizeAt = mOffset;
            const std::uint32_t bytes = read<std::uint32_t>(limit, "a metadata value size");
            if (bytes > limit - mOffset) {
                fail(sizeAt, entry + " declares a value of " + std::to_string(bytes) +
                                 " bytes but only " + std::to_string(limit - mOffset) + " remain");
            }
            // What OpenVDB reads of the value depends on its type: a string or an unknown type
            // the declared bytes, a fixed-size type its own size whatever is declared.
            if (type == openvdb::io::DelayedLoadMetadata::staticTypeName()) {
                delayedLoad(bytes, limit, entry, treeBytes);
            } else if (type != openvdb::StringMetadata::staticTypeName() && openvdb::Metadata::isRegisteredType(type)) {
                const std::uint32_t fixed = openvdb::Metadata::createMetadata(type)->size();
                if (bytes != fixed) {
                    fail(sizeAt, entry + " declares a '" + type + "' value of " + std::to_string(bytes) + " bytes; a '" + type +
                                     "' value is " + std::to_string(fixed) + " bytes");
                }
                seek(mOffset + bytes);
            } else {
                seek(mOffset + bytes);
            }
        }
    }
    /// The type name of a grid's transform (math::Transform::read); the map after it is not read.
    void transform(std::uint64_t limit) { string(limit, "the grid's transform type name"); }

private:
    /// @brief io::DelayedLoadMetadata (`__delayedload`): a leaf count, then a mask byte and a
    /// compressed size per leaf, each array raw or Blosc-compressed. OpenVDB allocates the count
    /// and the Blosc header's uncompressed size before it decompresses anything.
    void delayedLoad(std::uint32_t declared, std::uint64_t limit, const std::string& entry, std::uint64_t treeBytes)
    {
        if (declared == 0) return;  // OpenVDB reads nothing then
        const std::uint64_t start = mOffset;
        const std::uint32_t count = read<std::uint32_t>(limit, "the delayed-load leaf count");
        if (count > treeBytes) {
            fail(start, entry + " (delayed-load metadata) declares " + std::to_string(count) + " leaves but the grid holds only " +
                            std::to_string(treeBytes) + " bytes (a leaf takes at least one)");
        }
        const auto array = [&](std::uint32_t bytes, std::uint64_t itemSize, const char* what) {
            const std::uint64_t expected = std::uint64_t(count) * itemSize;
            if (bytes == 0) {
                skip(expected, limit, std::string("the delayed-load ") + what);
                return;
            }
            // A Blosc buffer: a 16-byte header whose uncompressed size (bytes 4-7) OpenVDB
            // allocates and whose compressed size (bytes 12-15) Blosc reads up to.
            const std::uint64_t at = mOffset;
            require(bytes, limit, std::string("the compressed delayed-load ") + what);
            if (bytes < 16) fail(at, entry + ": a compressed delayed-load " + what + " of " + std::to_string(bytes) + " bytes is shorter than Blosc's 16-byte header");
            std::uint32_t header[4];
            mIn.read(reinterpret_cast<char*>(header), sizeof(header));
            if (!mIn) fail(at, std::string("cannot read the Blosc header of the delayed-load ") + what);
            const std::uint32_t rawBytes = header[1], blockBytes = header[3];
            if (!(rawBytes == expected || (expected <= 128 && rawBytes == 128))) {  // 128: OpenVDB pads small arrays
                fail(at, entry + ": the compressed delayed-load " + what + " declares " + std::to_string(rawBytes) + " bytes uncompressed; " +
                             std::to_string(count) + " leaves make " + std::to_string(expected));
            }
            if (blockBytes > bytes) {
                fail(at, entry + ": the compressed delayed-load " + what + " declares " + std::to_string(blockBytes) +
                             " compressed bytes in a buffer of " + std::to_string(bytes));
            }
            seek(at + bytes);
        };
        array(read<std::uint32_t>(limit, "the delayed-load mask size"), sizeof(openvdb::io::DelayedLoadMetadata::MaskType), "mask");
        const std::uint32_t sizesBytes = read<std::uint32_t>(limit, "the delayed-load sizes size");
        if (sizesBytes != std::numeric_limits<std::uint32_t>::max()) {
            array(sizesBytes, sizeof(openvdb::io::DelayedLoadMetadata::CompressedSizeType), "compressed sizes");
        }
        // OpenVDB skips what the value declares beyond what it read.
        const std::uint64_t used = mOffset - start;
        if (used < declared) seek(start + declared);
    }

    std::ifstream mIn;
    std::string mWhere;
    std::uint64_t mSize = 0, mOffset = 0;
};

} // namespace

void checkVdbFileLayout(const std::string& path, const std::string& where)
{
    initializeOpenVdb();  // the metadata types OpenVDB will read by are registered then
    LayoutReader in(path, where);
    const std::uint64_t end = in.size();
    // Header (io::Archive::readHeader): magic, format version (before 211 as three numbers),
    // library version (from 211), whether grids have offsets (from 212), one compression flag
    // (220 and 221), then the UUID (36 characters from 218, 16 bytes before).
    if (end < 8 || in.read<std::int64_t>(end, "the magic number") != std::int64_t(openvdb::OPENVDB_MAGIC)) {
        throw FormatError(where + ": not a readable VDB file (the first 8 bytes are not OpenVDB's magic number)");
    }
    std::uint32_t version = in.read<std::uint32_t>(end, "the file format version");
    if (version < 211) {
        // OpenVDB's arithmetic, wrapping as its uint32 does.
        const std::uint32_t minor = in.read<std::uint32_t>(end, "the file format minor version");
        const std::uint32_t patch = in.read<std::uint32_t>(end, "the file format patch version");
        version = 100u * version + 10u * minor + patch;
    }
    if (version > openvdb::OPENVDB_FILE_VERSION) {
        in.fail(8, "format version " + std::to_string(version) + " is newer than the " +
                       std::to_string(openvdb::OPENVDB_FILE_VERSION) + " this OpenVDB reads");
    }
    if (version >= 211) in.skip(8, end, "the library version");
    bool hasOffsets = true;
    if (version >= 212) hasOffsets = in.read<char>(end, "the grid offsets flag") != 0;
    if (version >= openvdb::OPENVDB_FILE_VERSION_SELECTIVE_COMPRESSION && version < openvdb::OPENVDB_FILE_VERSION_NODE_MASK_COMPRESSION) {
        in.skip(1, end, "the compression flag");
    }
    if (version >= openvdb::OPENVDB_FILE_VERSION_BOOST_UUID) in.uuidText(end);
    else in.skip(16, end, "the UUID");
    in.metadata(end, "the file's metadata", end);

    // Grid descriptors (io::GridDescriptor::read): name, type, instance parent (from 216), then the
    // grid's start, data block start and end; the next descriptor starts at the grid's end.
    const bool instancing = version >= openvdb::OPENVDB_FILE_VERSION_GRID_INSTANCING;
    const std::uint64_t minDescriptor = instancing ? 36 : 32;
    const std::uint64_t countAt = in.offset();
    const std::uint32_t count = in.read<std::uint32_t>(end, "the grid count");
    if (count > (end - in.offset()) / minDescriptor) {
        in.fail(countAt, "the file declares " + std::to_string(std::int32_t(count)) + " grids but only " +
                             std::to_string(end - in.offset()) + " bytes remain (a grid descriptor alone needs " +
                             std::to_string(minDescriptor) + ")");
    }
    // Each grid: its compression flags (from 222) and metadata, then (from 216) its transform's
    // type name, all before its data block.
    const auto gridHead = [&](const std::string& name, std::uint64_t limit, std::uint64_t treeBytes) {
        if (version >= openvdb::OPENVDB_FILE_VERSION_NODE_MASK_COMPRESSION) in.read<std::uint32_t>(limit, "the grid's compression flags");
        in.metadata(limit, "grid '" + name + "' metadata", treeBytes);
        if (instancing) in.transform(limit);
    };
    for (std::uint32_t g = 0; g < count; ++g) {
        const std::uint64_t descAt = in.offset();
        const std::string name = in.string(end, "a grid name");
        in.string(end, "a grid type name");
        if (instancing) in.string(end, "a grid's instance parent name");
        const std::int64_t gridPos = in.read<std::int64_t>(end, "a grid start offset");
        const std::int64_t blockPos = in.read<std::int64_t>(end, "a grid data offset");
        const std::int64_t endPos = in.read<std::int64_t>(end, "a grid end offset");
        if (!hasOffsets) {
            // Grids follow their descriptors one after another (a stream written without offsets):
            // the first grid's head is checked; where it ends and the next begins only OpenVDB's
            // tree reader knows.
            gridHead(name, end, end - in.offset());
            return;
        }
        if (!(std::int64_t(in.offset()) <= gridPos && gridPos <= blockPos && blockPos <= endPos && std::uint64_t(endPos) <= end)) {
            in.fail(descAt, "grid " + std::to_string(g) + " ('" + name + "') has start " + std::to_string(gridPos) + ", data " +
                                std::to_string(blockPos) + " and end " + std::to_string(endPos) + "; they must satisfy " +
                                std::to_string(in.offset()) + " <= start <= data <= end <= " + std::to_string(end) + " (the file size)");
        }
        in.seek(std::uint64_t(gridPos));
        gridHead(name, std::uint64_t(blockPos), std::uint64_t(endPos - gridPos));
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
    checkVdbFileLayout(path, where);
    prescanVdbFile(path, where);  // every chunk, count and string bounded before OpenVDB reads it (VdbPrescan.h)
    try {
        file.open(/*delayLoad=*/false);
    } catch (const openvdb::Exception& e) {
        throw FormatError(where + ": not a readable VDB file (" + std::string(e.what()) + ")");
    }
}

/// The path whose read budget this thread is in (withinReadBudget()), or null.
thread_local const std::string* tBudgetedPath = nullptr;

/// withinReadBudget() for a read that returns its result.
template<typename ReadT>
auto budgetedRead(const std::string& path, const std::string& where, ReadT&& read) -> decltype(read())
{
    decltype(read()) result;
    withinReadBudget(path, where, [&] { result = read(); });
    return result;
}

std::string listNames(const std::vector<std::string>& names)
{
    if (names.empty()) return "the file has no grids";
    std::string s = "the file has ";
    for (std::size_t i = 0; i < names.size(); ++i) s += (i ? ", '" : "'") + names[i] + "'";
    return s;
}

} // namespace

void withinReadBudget(const std::string& path, const std::string& where, const std::function<void()>& read)
{
    requireRegularFile(path, where);
    if (tBudgetedPath && *tBudgetedPath == path) return read();
    std::error_code ec;
    const std::uintmax_t size = std::filesystem::file_size(path, ec);
    const std::uint64_t bytes = ec ? 0 : std::uint64_t(size);
    const std::uint64_t rule = readBudgetBytes(bytes, std::numeric_limits<std::uint64_t>::max());
    struct PathScope  // this thread reads @a path until the scope ends, however it ends
    {
        const std::string* outer = tBudgetedPath;
        explicit PathScope(const std::string& p) { tBudgetedPath = &p; }
        ~PathScope() { tBudgetedPath = outer; }
    };
    try {
        const PathScope scope(path);
        AllocationBudget budget(readBudgetBytes(bytes));
        read();
    } catch (const BudgetExceeded& e) {
        const std::string asked = where + ": reading it asks for " + formatBytes(e.requested()) + " with " + formatBytes(e.live()) + " held";
        if (e.limit() == rule)
            throw LimitError(asked + ", past the budget of " + formatBytes(rule) + " (" + std::to_string(kReadBudgetPerFileByte) + " x its " +
                             formatBytes(bytes) + " + " + formatBytes(kReadBudgetFloor) +
                             "): the file declares more data than it can hold (damaged, or not what it claims)");
        throw LimitError(asked + ", more than the " + formatBytes(e.limit()) +
                         (e.limit() == availableMemoryBytes() ? " available (MemAvailable)" : " left to this read") +
                         "; free memory or read it on a larger machine");
    } catch (const std::bad_alloc&) {
        throw FormatError(where + ": " + kTreeSizes);
    } catch (const std::length_error&) {
        throw FormatError(where + ": " + kTreeSizes);
    }
}

openvdb::GridPtrVec readVdbGrids(const std::string& path, const std::string& where)
{
    initializeOpenVdb();
    return budgetedRead(path, where, [&] {
        openvdb::io::File file(path);
        openFile(file, path, where);
        try {
            openvdb::GridPtrVecPtr grids = file.getGrids();
            file.close();
            return grids ? *grids : openvdb::GridPtrVec{};
        } catch (const openvdb::Exception& e) {
            throw FormatError(where + ": cannot read the grids (" + std::string(e.what()) + ")");
        }
    });
}

std::vector<std::string> vdbGridNames(const std::string& path, const std::string& where)
{
    initializeOpenVdb();
    return budgetedRead(path, where, [&] {
        openvdb::io::File file(path);
        openFile(file, path, where);
        std::vector<std::string> names;
        for (auto it = file.beginName(); it != file.endName(); ++it) names.push_back(it.gridName());
        file.close();
        return names;
    });
}

openvdb::GridBase::Ptr readVdbGrid(const std::string& path, const std::string& name,
                                   const std::string& where)
{
    initializeOpenVdb();
    return budgetedRead(path, where, [&] {
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
        }
    });
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
