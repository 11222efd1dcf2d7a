#include "VdbPrescan.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/io/MappedFile.h>

#include <openvdb/openvdb.h>
#include <openvdb/points/PointDataGrid.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cstdint>
#include <cstring>
#include <map>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace vdbhair {

namespace {

struct ScanError : std::runtime_error {
    uint64_t at;
    ScanError(uint64_t a, const std::string& m) : std::runtime_error(m), at(a) {}
};

// What the tree's value type means on disk.
struct ValueInfo {
    uint32_t size = 0;      // sizeof(ValueType): background, tiles, inactive values
    uint32_t halfSize = 0;  // sizeof(RealToHalf<ValueType>::HalfT) if real, else 0
    bool isBool = false;
    bool isPoints = false;
    const char* name = "";
};

bool valueInfoFor(std::string_view treeType, ValueInfo& v)
{
    static const struct { const char* n; ValueInfo v; } table[] = {
        {"Tree_float_5_4_3",       {4, 2, false, false, "float"}},
        {"Tree_double_5_4_3",      {8, 2, false, false, "double"}},
        {"Tree_int32_5_4_3",       {4, 0, false, false, "int32"}},
        {"Tree_int64_5_4_3",       {8, 0, false, false, "int64"}},
        {"Tree_bool_5_4_3",        {1, 0, true, false, "bool"}},
        {"Tree_vec3s_5_4_3",       {12, 6, false, false, "vec3s"}},
        {"Tree_vec3d_5_4_3",       {24, 6, false, false, "vec3d"}},
        {"Tree_vec3i_5_4_3",       {12, 0, false, false, "vec3i"}},
        {"Tree_ptdataidx32_5_4_3", {4, 0, false, true, "ptdataidx32"}},
    };
    for (const auto& t : table) if (treeType == t.n) { v = t.v; return true; }
    return false;
}

// OpenVDB constants mirrored (io/Compression.h, points/AttributeArray.h, StreamCompression.h)
enum : uint32_t { C_ZIP = 0x1, C_MASK = 0x2, C_BLOSC = 0x4 };
enum : uint8_t { NO_MASK_AND_ALL_VALS = 6 };
constexpr uint64_t BLOSC_OVERHEAD = 16;  // BLOSC_MAX_OVERHEAD
constexpr uint64_t BLOSC_PAD = 128;      // compression::BLOSC_PAD_BYTES
constexpr uint64_t PAGE_SIZE = 1024 * 1024;  // compression::PageSize
constexpr uint8_t WRITESTRIDED = 0x1, WRITEUNIFORM = 0x2, WRITEPAGED = 0x8;
constexpr uint8_t CONSTANTSTRIDE = 0x8;

struct Stats {
    uint64_t chunks = 0;        // compressed/uncompressed data chunks checked
    uint64_t bloscHeaders = 0;  // blosc headers checked
    uint64_t leaves = 0, internals = 0, pages = 0, arrays = 0;
    uint64_t declaredBytes = 0; // destination bytes OpenVDB will allocate for what it reads
};

// A field the file declares (for --list: the mutation tests aim at these).
struct Field { const char* kind; uint64_t off; uint64_t dest; };

class Scanner {
public:
    Scanner(const uint8_t* base, uint64_t size) : mBase(base), mSize(size), mLimit(size) {}
    Stats stats;
    std::vector<Field>* list = nullptr;

    void scanFile()
    {
        header();
        metaMap("file metadata", nullptr);
        const uint64_t countAt = mPos;
        const uint32_t count = rd<uint32_t>("grid count");
        if (int32_t(count) < 0 || count > (mSize - mPos) / 36)
            fail(countAt, "grid count " + std::to_string(int32_t(count)) + " impossible in the remaining bytes");
        for (uint32_t g = 0; g < count; ++g) grid(g);
        // Archive::write puts nothing after the last grid.  OpenVDB ignores trailing bytes, but a
        // walk that ends early means a size read differently from how it was written.
        if (mPos != mSize) fail(mPos, "the last grid ends " + std::to_string(mSize - mPos) + " bytes before the end of the file");
    }

private:
    const uint8_t* mBase;
    uint64_t mSize, mPos = 0, mLimit;
    uint32_t mVersion = 0;
    bool mHasOffsets = true;
    // per grid
    uint32_t mCompression = 0;
    bool mHalf = false;
    ValueInfo mVal;
    std::string mGridName;
    int64_t mDelayedCount = -1;   // leaf count declared by __delayedload metadata, -1 if none
    struct Leaf { uint64_t maskOff; int32_t x, y, z; };
    std::vector<Leaf> mLeaves;

    // ---------- primitive reads, every one bounded by mLimit (grid end or file size)
    void note(const char* kind, uint64_t off, uint64_t dest) { if (list) list->push_back({kind, off, dest}); }
    [[noreturn]] void fail(uint64_t at, const std::string& m) const
    {
        throw ScanError(at, (mGridName.empty() ? "" : "grid '" + mGridName + "': ") + m);
    }
    void need(uint64_t n, const char* what) const
    {
        if (mPos > mLimit || n > mLimit - mPos)
            fail(mPos, std::string(what) + " needs " + std::to_string(n) + " bytes, " +
                           std::to_string(mPos > mLimit ? 0 : mLimit - mPos) + " remain" +
                           (mLimit == mSize ? " in the file" : " in the grid"));
    }
    template<typename T> T rd(const char* what)
    {
        need(sizeof(T), what);
        T v;
        std::memcpy(&v, mBase + mPos, sizeof(T));
        mPos += sizeof(T);
        return v;
    }
    template<typename T> T peekAt(uint64_t off) const { T v; std::memcpy(&v, mBase + off, sizeof(T)); return v; }
    void skip(uint64_t n, const char* what) { need(n, what); mPos += n; }
    std::string_view str(const char* what)
    {
        note("strlen", mPos, 0);
        const uint32_t n = rd<uint32_t>(what);
        need(n, what);
        std::string_view s(reinterpret_cast<const char*>(mBase + mPos), n);
        mPos += n;
        return s;
    }
    bool rdBool(const char* what)
    {
        const uint8_t b = rd<uint8_t>(what);
        if (b > 1) fail(mPos - 1, std::string(what) + " is byte " + std::to_string(b) + ", not a bool (0 or 1)");
        return b;
    }
    void value(const char* what)  // one ValueType as stored raw (background, tile, inactive value)
    {
        if (mVal.isBool) rdBool(what); else skip(mVal.size, what);
    }

    // ---------- header (io::Archive::readHeader, Archive.cc:956-1026)
    void header()
    {
        if (mSize < 8 || peekAt<int64_t>(0) != int64_t(openvdb::OPENVDB_MAGIC)) fail(0, "not a VDB file (magic)");
        mPos = 8;
        mVersion = rd<uint32_t>("file format version");
        if (mVersion < 222 || mVersion > openvdb::OPENVDB_FILE_VERSION)
            fail(8, "file format " + std::to_string(mVersion) + " is outside 222..224, which this pre-scan covers");
        skip(8, "library version");
        mHasOffsets = rd<uint8_t>("grid offsets flag") != 0;
        // UUID as 36 ASCII characters 8-4-4-4-12 (boost operator>>, format >= 218)
        need(36, "UUID");
        for (int i = 0; i < 36; ++i) {
            const char c = char(mBase[mPos + i]);
            const bool dash = (i == 8 || i == 13 || i == 18 || i == 23);
            if (dash ? c != '-' : !std::isxdigit(static_cast<unsigned char>(c))) fail(mPos, "UUID is not 8-4-4-4-12 hex");
        }
        mPos += 36;
    }

    // ---------- MetaMap::readMeta (MetaMap.cc:52-85), Metadata::read (Metadata.h:189)
    void metaMap(const char* what, int64_t* delayedCount)
    {
        const uint64_t at = mPos;
        note("metacount", mPos, 0);
        const uint32_t count = rd<uint32_t>("metadata count");
        if (count > (mLimit - mPos) / 12) fail(at, std::string(what) + ": " + std::to_string(count) + " entries cannot fit");
        for (uint32_t i = 0; i < count; ++i) {
            str("metadata name");
            const std::string type(str("metadata type name"));
            const uint64_t sizeAt = mPos;
            note(type == "__delayedload" ? "dlsize" : "metasize", mPos, 0);
            const uint32_t bytes = rd<uint32_t>("metadata value size");
            need(bytes, "metadata value");
            if (type == "__delayedload") {
                delayedLoad(bytes, delayedCount);
                continue;
            }
            if (type != "string" && openvdb::Metadata::isRegisteredType(type)) {
                // TypedMetadata<T>::readValue reads sizeof(T) whatever is declared (Metadata.h:282-286)
                const uint32_t fixed = openvdb::Metadata::createMetadata(type)->size();
                if (bytes != fixed)
                    fail(sizeAt, "metadata of type '" + type + "' declares " + std::to_string(bytes) + " bytes, the type has " + std::to_string(fixed));
            }
            mPos += bytes;  // string / unknown: exactly `bytes` (StringMetadata::readValue, UnknownMetadata)
        }
    }

    // DelayedLoadMetadata::readValue (DelayedLoadMetadata.cc:147-225)
    void delayedLoad(uint32_t declared, int64_t* delayedCount)
    {
        if (declared == 0) return;
        const uint64_t start = mPos, end = mPos + declared;
        const uint64_t saveLimit = mLimit;
        mLimit = end;  // OpenVDB reads past `declared` if the content says so; we do not allow that
        const uint32_t count = rd<uint32_t>("delayed-load leaf count");
        auto array = [&](uint32_t bytes, uint64_t item, const char* what) {
            const uint64_t expect = uint64_t(count) * item;
            if (bytes == 0) { skip(expect, what); return; }
            need(bytes, what);
            bloscHeader(mPos, bytes, expect, /*allowPad=*/true, what);
            mPos += bytes;
        };
        array(rd<uint32_t>("delayed-load mask size"), 1, "delayed-load mask");
        const uint32_t sizes = rd<uint32_t>("delayed-load sizes size");
        if (sizes != 0xffffffffu) array(sizes, 8, "delayed-load compressed sizes");
        if (mPos > end) fail(start, "delayed-load metadata overruns its declared size");
        mPos = end;
        mLimit = saveLimit;
        if (delayedCount) *delayedCount = count;
    }

    // ---------- blosc 1.x header: version, versionlz, flags, typesize, nbytes, blocksize, cbytes
    void bloscHeader(uint64_t off, uint64_t chunk, uint64_t expectNbytes, bool allowPad, const char* what)
    {
        ++stats.bloscHeaders;
        note("blosc", off, expectNbytes);
        if (chunk < BLOSC_OVERHEAD) fail(off, std::string(what) + ": blosc chunk of " + std::to_string(chunk) + " bytes is shorter than its 16-byte header");
        const uint32_t nbytes = peekAt<uint32_t>(off + 4), blocksize = peekAt<uint32_t>(off + 8), cbytes = peekAt<uint32_t>(off + 12);
        if (cbytes != chunk)
            fail(off, std::string(what) + ": blosc header says " + std::to_string(cbytes) + " compressed bytes in a chunk of " + std::to_string(chunk));
        const bool padOk = allowPad && expectNbytes <= BLOSC_PAD && nbytes == BLOSC_PAD;
        if (nbytes != expectNbytes && !padOk)
            fail(off, std::string(what) + ": blosc header says " + std::to_string(nbytes) + " bytes uncompressed, the destination holds " + std::to_string(expectNbytes));
        if (nbytes == 0 && chunk != BLOSC_OVERHEAD) fail(off, std::string(what) + ": empty blosc chunk of " + std::to_string(chunk) + " bytes");
        if (nbytes > 0 && (blocksize == 0 || blocksize > nbytes))
            fail(off, std::string(what) + ": blosc block size " + std::to_string(blocksize) + " is not within 1.." + std::to_string(nbytes));
    }

    // ---------- io::readData (Compression.h:246-268), unzipFromStream / bloscFromStream (Compression.cc:122-307)
    void dataChunk(uint64_t destBytes, const char* what)
    {
        ++stats.chunks;
        stats.declaredBytes += destBytes;
        if (!(mCompression & (C_BLOSC | C_ZIP))) { skip(destBytes, what); return; }
        const uint64_t at = mPos;
        note((mCompression & C_BLOSC) ? "chunk64blosc" : "chunk64zip", at, destBytes);
        const int64_t c = rd<int64_t>(what);
        if (c <= 0) {
            // negative: uncompressed, read straight into the destination -> must be exactly its size
            if (c == INT64_MIN || uint64_t(-c) != destBytes)
                fail(at, std::string(what) + ": uncompressed chunk of " + std::to_string(c == INT64_MIN ? 0 : -c) +
                             " bytes for a destination of " + std::to_string(destBytes));
            skip(destBytes, what);
            return;
        }
        if (mCompression & C_BLOSC) {
            if (uint64_t(c) > destBytes + BLOSC_OVERHEAD)
                fail(at, std::string(what) + ": blosc chunk of " + std::to_string(c) + " bytes for a destination of " +
                             std::to_string(destBytes) + " (at most destination + 16)");
            need(uint64_t(c), what);
            bloscHeader(mPos, uint64_t(c), destBytes, /*allowPad=*/false, what);
        } else {
            if (uint64_t(c) > destBytes)
                fail(at, std::string(what) + ": zip chunk of " + std::to_string(c) + " bytes for a destination of " +
                             std::to_string(destBytes) + " (OpenVDB writes zip only when smaller)");
            need(uint64_t(c), what);
        }
        stats.declaredBytes += uint64_t(c);  // the temporary compressed buffer
        mPos += uint64_t(c);
    }

    static uint64_t countOn(const uint8_t* mask, uint64_t bytes)
    {
        uint64_t n = 0;
        for (uint64_t i = 0; i < bytes; i += 8) { uint64_t w; std::memcpy(&w, mask + i, 8); n += uint64_t(__builtin_popcountll(w)); }
        return n;
    }

    // ---------- io::readCompressedValues (Compression.h:463-586)
    void compressedValues(uint64_t count, uint64_t maskOff, uint64_t maskBytes, const char* what)
    {
        const uint64_t at = mPos;
        note("nodemeta", at, count);
        const uint8_t meta = rd<uint8_t>("per-node compression byte");
        if (meta > NO_MASK_AND_ALL_VALS) fail(at, std::string(what) + ": per-node compression byte " + std::to_string(meta) + " is not 0..6");
        // writeCompressedValues writes 6 whenever active-mask compression is off (Compression.h:656-659)
        if (!(mCompression & C_MASK) && meta != NO_MASK_AND_ALL_VALS) fail(at, std::string(what) + ": per-node compression byte " + std::to_string(meta) + " without active-mask compression (OpenVDB writes 6)");
        if (meta == 2 || meta == 4 || meta == 5) value("inactive value");
        if (meta == 5) value("second inactive value");
        if (meta == 3 || meta == 4 || meta == 5) skip(count / 8, "selection mask");
        uint64_t n = count;
        if ((mCompression & C_MASK) && meta != NO_MASK_AND_ALL_VALS) n = countOn(mBase + maskOff, maskBytes);
        const bool half = mHalf && mVal.halfSize != 0;
        if (half) {
            if (n < 1) return;  // HalfReader::read returns before reading anything (Compression.h:307)
            stats.declaredBytes += n * mVal.halfSize;  // temporary half buffer
            dataChunk(n * mVal.halfSize, what);
        } else {
            dataChunk(n * mVal.size, what);
        }
    }

    // ---------- transform (Transform.cc:68-150, Maps.h read())
    void mapBody(std::string_view type, int depth)
    {
        if (type == "AffineMap" || type == "UnitaryMap") skip(128, "map");
        else if (type == "ScaleMap" || type == "UniformScaleMap") skip(120, "map");
        else if (type == "TranslationMap") skip(24, "map");
        else if (type == "ScaleTranslateMap" || type == "UniformScaleTranslateMap") skip(144, "map");
        else if (type == "NonlinearFrustumMap" && depth == 0) {
            skip(48 + 8 + 8, "frustum map");
            mapBody(str("frustum second map type"), 1);
        } else fail(mPos, "transform map type '" + std::string(type) + "' is not one OpenVDB 10 reads here");
    }

    // ---------- one grid (GridDescriptor::read GridDescriptor.cc:73-106; Archive.cc doReadGrid:1125-1222)
    void grid(uint32_t index)
    {
        mGridName.clear();
        const uint64_t descAt = mPos;
        mGridName = std::string(str("grid name"));
        std::string type(str("grid type"));
        mHalf = false;
        const std::string halfSuffix = "_HalfFloat";
        if (type.size() > halfSuffix.size() && type.compare(type.size() - halfSuffix.size(), halfSuffix.size(), halfSuffix) == 0) {
            mHalf = true;
            type.resize(type.size() - halfSuffix.size());
        }
        const bool instance = !str("instance parent").empty();
        const int64_t gridPos = rd<int64_t>("grid offset"), blockPos = rd<int64_t>("block offset"), endPos = rd<int64_t>("end offset");
        if (!valueInfoFor(type, mVal)) fail(descAt, "grid type '" + type + "' is not one vdbhair reads");
        if (mHasOffsets) {
            // io::Stream (the path that reads our validated bytes) reads the grid right after its
            // descriptor, where Archive::writeGrid puts it (Archive.cc:1385-1396)
            if (gridPos != int64_t(mPos)) fail(descAt, "grid does not start right after its descriptor");
            // Archive::writeGridInstance leaves the block offset 0 (Archive.cc:1447-1475)
            const bool ordered = instance ? (int64_t(mPos) <= gridPos && gridPos <= endPos)
                                          : (int64_t(mPos) <= gridPos && gridPos <= blockPos && blockPos <= endPos);
            if (!ordered || uint64_t(endPos) > mSize)
                fail(descAt, "offsets " + std::to_string(gridPos) + "/" + std::to_string(blockPos) + "/" + std::to_string(endPos) + " out of order or past the file");
            mPos = uint64_t(gridPos);
            mLimit = uint64_t(endPos);
        } else {
            mLimit = mSize;  // io::Stream layout: the grid follows its descriptor
        }
        mCompression = rd<uint32_t>("grid compression flags");
        if (mCompression & ~uint32_t(C_ZIP | C_MASK | C_BLOSC)) fail(mPos - 4, "unknown compression flags");
        mDelayedCount = -1;
        metaMap("grid metadata", &mDelayedCount);
        mapBody(str("transform map type"), 0);
        if (!instance) {
            mLeaves.clear();
            topology();
            if (mHasOffsets && mPos != uint64_t(blockPos))
                fail(mPos, "topology ends at " + std::to_string(mPos) + ", the descriptor's block offset is " + std::to_string(blockPos));
            if (mDelayedCount >= 0 && uint64_t(mDelayedCount) != mLeaves.size())
                fail(mPos, "delayed-load metadata declares " + std::to_string(mDelayedCount) + " leaves, the tree has " + std::to_string(mLeaves.size()));
            if (mVal.isPoints) pointBuffers(); else leafBuffers();
        }
        if (mHasOffsets) {
            if (!instance && mPos != uint64_t(endPos))
                fail(mPos, "grid ends at " + std::to_string(mPos) + ", the descriptor's end offset is " + std::to_string(endPos));
            mPos = uint64_t(endPos);  // File::readGridDescriptors: gd.seekToEnd
        }
        mLimit = mSize;
        (void)index;
    }

    // ---------- topology: TreeBase::readTopology (Tree.h:1083), RootNode::readTopology (RootNode.h:2354-2463),
    // InternalNode::readTopology (InternalNode.h:2208-2260), LeafNode::readTopology (LeafNode.h:1280)
    void topology()
    {
        const int32_t bufferCount = rd<int32_t>("buffer count");
        if (bufferCount != 1) fail(mPos - 4, "buffer count " + std::to_string(bufferCount) + " (OpenVDB writes 1)");
        // PointDataLeafNode(PartialCreate, origin, background) asserts the value is zero
        // (PointDataGrid.h:314-317; Debian's build keeps asserts: SIGABRT)
        if (mVal.isPoints) need(mVal.size, "background");
        if (mVal.isPoints && peekAt<uint32_t>(mPos) != 0) fail(mPos, "a points tree's background must be 0");
        value("background");
        const uint64_t at = mPos;
        note("rootcounts", at, 0);
        const uint32_t numTiles = rd<uint32_t>("root tile count"), numChildren = rd<uint32_t>("root child count");
        const uint64_t tileBytes = 12 + mVal.size + 1, childMin = 12 + 4096 + 4096 + 1;
        if (numTiles > (mLimit - mPos) / tileBytes ||
            numChildren > (mLimit - mPos - uint64_t(numTiles) * tileBytes) / childMin)
            fail(at, std::to_string(numTiles) + " root tiles and " + std::to_string(numChildren) + " children cannot fit");
        if (numTiles == 0 && numChildren == 0) return;
        // mTable is a std::map<Coord,...>: buffers are read in key order, and a repeated key
        // silently replaces (and leaks) a node.  OpenVDB writes keys in order: require that.
        std::vector<std::array<int32_t, 3>> tileKeys;  // <= numTiles, bounded above
        std::array<int32_t, 3> prev{};
        for (uint32_t n = 0; n < numTiles; ++n) {
            std::array<int32_t, 3> k{rd<int32_t>("tile x"), rd<int32_t>("tile y"), rd<int32_t>("tile z")};
            checkKey(k, n ? &prev : nullptr, "root tile");
            prev = k;
            tileKeys.push_back(k);
            if (mVal.isPoints && (need(mVal.size, "tile value"), peekAt<uint32_t>(mPos) != 0)) fail(mPos, "a points tree's tile value must be 0");
            value("tile value");
            rdBool("tile active flag");
        }
        size_t t = 0;
        for (uint32_t n = 0; n < numChildren; ++n) {
            std::array<int32_t, 3> k{rd<int32_t>("child x"), rd<int32_t>("child y"), rd<int32_t>("child z")};
            checkKey(k, n ? &prev : nullptr, "root child");
            while (t < tileKeys.size() && tileKeys[t] < k) ++t;
            if (t < tileKeys.size() && tileKeys[t] == k) fail(mPos - 12, "root child key repeats a tile key");
            prev = k;
            internal(5, k);
        }
    }
    void checkKey(const std::array<int32_t, 3>& k, const std::array<int32_t, 3>* prev, const char* what)
    {
        for (int i = 0; i < 3; ++i)
            if (k[i] & 4095) fail(mPos - 12, std::string(what) + " origin is not a multiple of 4096");
        if (prev && !(*prev < k)) fail(mPos - 12, std::string(what) + " keys are not strictly increasing (x, y, z)");
    }
    void internal(int log2, const std::array<int32_t, 3>& origin)
    {
        ++stats.internals;
        const uint64_t numValues = uint64_t(1) << (3 * log2), maskBytes = numValues / 8;
        need(2 * maskBytes, "internal node masks");
        const uint64_t childMask = mPos, valueMask = mPos + maskBytes;
        mPos += 2 * maskBytes;
        compressedValues(numValues, valueMask, maskBytes, "internal node values");
        stats.declaredBytes += numValues * 8;  // the node's table (NodeUnion >= 8 bytes)
        const int childLog2Total = (log2 == 5) ? 7 : 3;  // child node TOTAL: 4+3 or 3
        for (uint64_t w = 0; w < numValues / 64; ++w) {
            uint64_t word = peekAt<uint64_t>(childMask + 8 * w);
            while (word) {
                const uint64_t i = 64 * w + uint64_t(__builtin_ctzll(word));
                word &= word - 1;
                // InternalNode offsetToLocalCoord: x = n >> 2*log2, y = (n >> log2) & (dim-1), z = n & (dim-1)
                const uint64_t dim = uint64_t(1) << log2;
                std::array<int32_t, 3> c{origin[0] + int32_t((i >> (2 * log2)) << childLog2Total),
                                         origin[1] + int32_t(((i >> log2) & (dim - 1)) << childLog2Total),
                                         origin[2] + int32_t((i & (dim - 1)) << childLog2Total)};
                if (log2 == 5) internal(4, c);
                else leafTopology(c);
            }
        }
    }
    void leafTopology(const std::array<int32_t, 3>& origin)
    {
        need(64, "leaf value mask");
        mLeaves.push_back({mPos, origin[0], origin[1], origin[2]});
        mPos += 64;
    }

    // ---------- leaf buffers: LeafNode::readBuffers (LeafNode.h:1324-1411), bool (LeafNodeBool.h:992-1030)
    void leafBuffers()
    {
        for (const Leaf& leaf : mLeaves) {
            ++stats.leaves;
            need(64, "leaf value mask (buffer copy)");
            // io::File (seekable) skips this copy; the delayed loader and io::Stream read it:
            // require it to equal the topology's mask so that every path sees one mask.
            note("leafmask", mPos, 0);
            if (std::memcmp(mBase + mPos, mBase + leaf.maskOff, 64) != 0) fail(mPos, "leaf mask in the buffers differs from the topology");
            mPos += 64;
            if (mVal.isBool) {
                const int32_t x = rd<int32_t>("leaf origin"), y = rd<int32_t>("leaf origin"), z = rd<int32_t>("leaf origin");
                if (x != leaf.x || y != leaf.y || z != leaf.z) fail(mPos - 12, "bool leaf origin differs from its place in the tree");
                skip(64, "bool leaf values");
                stats.declaredBytes += 64;
            } else {
                compressedValues(512, leaf.maskOff, 64, "leaf values");
            }
        }
    }

    // ---------- PointDataGrid: Grid::readBuffers multi-pass (Grid.h:1605-1620),
    // PointDataLeafNode::readBuffers (PointDataGrid.h:1148-1300)
    struct Array { uint32_t n; uint32_t expect; uint8_t sflags; };
    struct PageInfo { int64_t c; uint64_t u; };

    uint64_t storageSize(std::string_view vt, std::string_view codec, uint64_t at)
    {
        const openvdb::NamePair type{std::string(vt), std::string(codec)};
        auto it = mStorage.find(type);
        if (it != mStorage.end()) return it->second;
        if (!openvdb::points::AttributeArray::isRegistered(type))
            fail(at, "attribute type (" + type.first + ", " + type.second + ") is not registered");
        const uint64_t s = openvdb::points::AttributeArray::create(type, 1, 1)->storageTypeSize();
        mStorage[type] = s;
        return s;
    }
    std::map<openvdb::NamePair, uint64_t> mStorage;

    // AttributeSet::Descriptor::read (AttributeSet.cc:1351-1384): returns storage sizes per array
    std::vector<uint64_t> descriptor()
    {
        const uint64_t at = mPos;
        note("desccount", at, 0);
        const uint64_t n = rd<uint64_t>("descriptor array count");
        if (n > (mLimit - mPos) / 20 || n > 32765) fail(at, "descriptor declares " + std::to_string(n) + " arrays");
        std::vector<uint64_t> sizes;
        uint64_t groupArrays = 0;
        for (uint64_t i = 0; i < n; ++i) {
            const uint64_t tat = mPos;
            const std::string_view vt = str("attribute value type"), codec = str("attribute codec");
            sizes.push_back(storageSize(vt, codec, tat));
            if (codec == "grp") ++groupArrays;
        }
        std::vector<bool> seen(n, false);
        for (uint64_t i = 0; i < n; ++i) {
            validName(str("attribute name"));
            const uint64_t off = rd<uint64_t>("attribute index");
            if (off >= n || seen[off]) fail(mPos - 8, "attribute index " + std::to_string(off) + " out of range or repeated");
            seen[off] = true;
        }
        const uint64_t gat = mPos;
        const uint64_t groups = rd<uint64_t>("group count");
        if (groups > (mLimit - mPos) / 13) fail(gat, "descriptor declares " + std::to_string(groups) + " groups");
        for (uint64_t i = 0; i < groups; ++i) {
            validName(str("group name"));
            const uint64_t off = rd<uint64_t>("group offset");
            if (off >= groupArrays * 8) fail(mPos - 8, "group offset " + std::to_string(off) + " beyond the group arrays");
        }
        metaMap("descriptor metadata", nullptr);
        return sizes;
    }
    void validName(std::string_view s)
    {
        bool ok = !s.empty();
        for (char c : s) ok = ok && (std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '|' || c == ':');
        if (!ok) fail(mPos, "invalid attribute or group name");
    }
    // TypedAttributeArray::readMetadata (AttributeArray.h:1700-1745)
    Array arrayMetadata(uint64_t storage)
    {
        ++stats.arrays;
        const uint64_t at = mPos;
        note("arraybytes", at, 0);
        const uint64_t bytes = rd<uint64_t>("array byte count");
        const uint8_t flags = rd<uint8_t>("array flags");
        const uint8_t sflags = rd<uint8_t>("array serialization flags");
        const uint32_t size = rd<uint32_t>("array size");
        uint64_t stride = 1;
        if (sflags >= 0x10) fail(at, "unknown array serialization flags");
        if (sflags & WRITESTRIDED) stride = rd<uint32_t>("array stride");
        const bool uniform = sflags & WRITEUNIFORM;
        const unsigned __int128 elems = uniform ? 1 : ((flags & CONSTANTSTRIDE) ? (unsigned __int128)size * stride : stride);
        const unsigned __int128 expect = elems * storage;
        if (bytes < 6 || expect == 0 || expect > 0x7fffffff || bytes - 6 > 0x7fffffff)
            fail(at, "array declares " + std::to_string(bytes) + " bytes (expected 6 + " + std::to_string(uint64_t(expect)) + ", at most 2^31-1)");
        stats.declaredBytes += uint64_t(expect);
        return Array{uint32_t(bytes - 6), uint32_t(expect), sflags};
    }

    // The arrays of every leaf, as pass 1 declares them: leaf i's are arrays[start[i]..start[i+1]).
    struct LeafArrays {
        std::vector<uint64_t> start;
        std::vector<Array> arrays;
        size_t maxAttrs = 0;  // the most attributes of any leaf's descriptor
        // Array a of leaf @a leaf, or null when its descriptor has fewer.
        const Array* of(size_t leaf, size_t a) const
        {
            const uint64_t b = start[leaf], e = start[leaf + 1];
            return (b + a < e) ? &arrays[b + a] : nullptr;
        }
    };

    void pointBuffers()
    {
        const size_t L = mLeaves.size();
        const uint64_t at = mPos;
        note("passes", at, 0);
        const uint16_t numPasses = rd<uint16_t>("pass count");
        if (L == 0) {
            if (numPasses != 0) fail(at, "pass count " + std::to_string(numPasses) + " for a tree without leaves");
            return;
        }
        const std::vector<uint16_t> voxelBytes = voxelBufferSizes();
        const LeafArrays arrays = arrayMetadataPass();
        if (numPasses != 2 * arrays.maxAttrs + 4)
            fail(at, "pass count " + std::to_string(numPasses) + " for " + std::to_string(arrays.maxAttrs) + " attributes (OpenVDB writes 2n+4)");
        const std::vector<std::vector<PageInfo>> pages = pageHeaders(arrays);
        voxelBuffers(voxelBytes);
        arrayData(arrays, pages);
        // pass 2n+3: nothing read
    }
    // pass 0: voxel buffer sizes
    std::vector<uint16_t> voxelBufferSizes()
    {
        std::vector<uint16_t> voxelBytes(mLeaves.size());
        for (size_t i = 0; i < mLeaves.size(); ++i) { note("voxel16pass0", mPos, 2048); voxelBytes[i] = rd<uint16_t>("voxel buffer size"); }
        return voxelBytes;
    }
    // pass 1: descriptor (shared if header bit 0) and array metadata
    LeafArrays arrayMetadataPass()
    {
        const size_t L = mLeaves.size();
        LeafArrays out;
        out.start.resize(L + 1);
        std::vector<std::vector<uint64_t>> descs;
        bool shared = false;
        for (size_t i = 0; i < L; ++i) {
            if (!shared) {
                const uint8_t header = rd<uint8_t>("points leaf header");
                if (header > 1) fail(mPos - 1, "points leaf header " + std::to_string(header) + " (OpenVDB writes 0 or 1)");
                descs.push_back(descriptor());
                shared = header & 1;
            }
            const auto& d = descs.back();
            out.maxAttrs = std::max(out.maxAttrs, d.size());
            out.start[i] = out.arrays.size();
            for (uint64_t s : d) out.arrays.push_back(arrayMetadata(s));
        }
        out.start[L] = out.arrays.size();
        return out;
    }
    // passes 2..n+1: page headers (PagedInputStream::createHandle, StreamCompression.cc:488-507; Page::readHeader :307-326)
    std::vector<std::vector<PageInfo>> pageHeaders(const LeafArrays& arrays)
    {
        std::vector<std::vector<PageInfo>> pages(arrays.maxAttrs);
        for (size_t a = 0; a < arrays.maxAttrs; ++a) {
            uint64_t pageU = 0, used = 0;
            for (size_t i = 0; i < mLeaves.size(); ++i) {
                const Array* arr = arrays.of(i, a);
                if (!arr || !(arr->sflags & WRITEPAGED)) continue;
                if (arr->n != arr->expect)
                    fail(mPos, "paged array declares " + std::to_string(arr->n) + " bytes, its size, stride and type make " + std::to_string(arr->expect));
                if (used == pageU) {
                    const PageInfo p = pageHeader();
                    pages[a].push_back(p);
                    pageU = p.u;
                    used = 0;
                    ++stats.pages;
                }
                if (arr->n > pageU - used)
                    fail(mPos, "array of " + std::to_string(arr->n) + " bytes overruns its page (" + std::to_string(pageU - used) + " bytes left)");
                used += arr->n;
            }
            if (used != pageU) fail(mPos, "the last page of attribute " + std::to_string(a) + " is not filled exactly");
        }
        return pages;
    }
    // One page header: compressed size (negative: stored uncompressed), then the uncompressed one if compressed.
    PageInfo pageHeader()
    {
        const uint64_t hat = mPos;
        note("page32", hat, 0);
        const int32_t c = rd<int32_t>("page compressed size");
        uint64_t u;
        if (c > 0) {
            const int32_t ui = rd<int32_t>("page uncompressed size");
            if (ui <= c) fail(hat, "page: compressed " + std::to_string(c) + " not below uncompressed " + std::to_string(ui));
            u = uint64_t(ui);
        } else {
            if (c == 0 || c == INT32_MIN) fail(hat, "page size " + std::to_string(c));
            u = uint64_t(-int64_t(c));
        }
        if (int64_t(c) > 0 ? uint64_t(c) > mLimit - mPos : u > mLimit - mPos)
            fail(hat, "page of " + std::to_string(c) + " bytes cannot fit in the grid");
        return {c, u};
    }
    // pass n+2: voxel buffers (readCompressedValues<PointDataIndex32> PointDataGrid.h:44-100)
    void voxelBuffers(const std::vector<uint16_t>& voxelBytes)
    {
        for (size_t i = 0; i < mLeaves.size(); ++i) {
            ++stats.leaves;
            need(64, "leaf value mask (buffer copy)");
            if (std::memcmp(mBase + mPos, mBase + mLeaves[i].maskOff, 64) != 0) fail(mPos, "leaf mask in the buffers differs from the topology");
            mPos += 64;
            const uint64_t at2 = mPos;
            note("voxel16", at2, 2048);
            const uint16_t b = rd<uint16_t>("voxel buffer size");
            if (b != voxelBytes[i]) fail(at2, "voxel buffer size differs from pass 0");
            ++stats.chunks;
            stats.declaredBytes += 2048;
            if (b == 0xffff) { skip(2048, "voxel offsets"); continue; }
            need(b, "voxel offsets");
            bloscHeader(mPos, b, 2048, false, "voxel offsets");
            stats.declaredBytes += b + 2048 + BLOSC_OVERHEAD;  // temporaries in bloscDecompress
            mPos += b;
        }
    }
    // passes n+3..2n+2: array data (TypedAttributeArray::readPagedBuffers AttributeArray.h:1790-1845,
    // readBuffers :1751-1787, PagedInputStream::read StreamCompression.cc:510-524, Page::readBuffers :329-372)
    void arrayData(const LeafArrays& arrays, const std::vector<std::vector<PageInfo>>& pages)
    {
        for (size_t a = 0; a < arrays.maxAttrs; ++a) {
            size_t page = 0;
            uint64_t pageU = 0, used = 0;
            for (size_t i = 0; i < mLeaves.size(); ++i) {
                const Array* arr = arrays.of(i, a);
                if (!arr) continue;
                ++stats.chunks;
                if (arr->sflags & WRITEPAGED) {
                    if (used == pageU) {
                        const PageInfo& p = pages[a][page++];
                        pageData(p);
                        pageU = p.u;
                        used = 0;
                    }
                    used += arr->n;
                    continue;
                }
                unpagedArrayData(*arr);
            }
        }
    }
    // A page's bytes: blosc-compressed when its header's size is positive, else stored.
    void pageData(const PageInfo& p)
    {
        if (p.c > 0) {
            need(uint64_t(p.c), "page data");
            bloscHeader(mPos, uint64_t(p.c), p.u, /*allowPad=*/true, "page data");
            stats.declaredBytes += uint64_t(p.c) + 2 * std::max<uint64_t>(p.u, BLOSC_PAD);
            mPos += uint64_t(p.c);
        } else {
            skip(p.u, "page data");
            stats.declaredBytes += 2 * p.u;
        }
    }
    // unpaged: [blosc flag byte unless uniform] then exactly mCompressedBytes bytes
    void unpagedArrayData(const Array& arr)
    {
        uint8_t blosc = 0;
        if (!(arr.sflags & WRITEUNIFORM)) {
            blosc = rd<uint8_t>("array blosc flag");
            if (blosc > 1) fail(mPos - 1, "array blosc flag " + std::to_string(blosc));
        }
        need(arr.n, "array data");
        if (blosc) {
            bloscHeader(mPos, arr.n, arr.expect, /*allowPad=*/true, "array data");
            stats.declaredBytes += arr.n + std::max<uint64_t>(arr.expect, BLOSC_PAD) + BLOSC_OVERHEAD;
        } else if (arr.n != arr.expect) {
            fail(mPos, "array holds " + std::to_string(arr.n) + " bytes, its size, stride and type make " + std::to_string(arr.expect));
        }
        mPos += arr.n;
    }
};

} // namespace

bool prescanVdbFile(const std::string& path, const std::string& where, VdbPrescanStats* out, std::vector<VdbPrescanField>* fields)
{
    const MappedFile file(path, where);
    const auto* base = reinterpret_cast<const uint8_t*>(file.data());
    const uint64_t size = file.size();
    // Formats before 222 (no per-grid compression flags) are not walked.
    if (size >= 12) {
        uint32_t version;
        std::memcpy(&version, base + 8, 4);
        if (version < 222) return false;
    }
    Scanner s(base, size);
    std::vector<Field> seen;
    if (fields) s.list = &seen;
    try {
        s.scanFile();
    } catch (const ScanError& e) {
        throw FormatError(where + ": not a VDB file this reader can bound: at byte " + std::to_string(e.at) + ": " + e.what());
    }
    if (fields) {
        fields->clear();
        for (const Field& f : seen) fields->push_back({f.kind, f.off, f.dest});
    }
    if (out) {
        out->leaves = s.stats.leaves;
        out->chunks = s.stats.chunks;
        out->arrays = s.stats.arrays;
        out->pages = s.stats.pages;
        out->declaredBytes = s.stats.declaredBytes;
    }
    return true;
}

} // namespace vdbhair
