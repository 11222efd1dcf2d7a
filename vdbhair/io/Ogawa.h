/// @file Ogawa.h
/// @brief The Ogawa container that Alembic archives are stored in (Alembic 1.5 and later), written
/// and read by vdbhair itself for AbcFile.h (Debian packages no Alembic library).
///
/// An Ogawa file is a tree of *groups* and *data* blocks addressed by byte offsets:
///
/// ```
/// bytes 0-4   "Ogawa"
/// byte  5     0xff once the writer has finished ("frozen"), 0 while it writes
/// bytes 6-7   format version, big-endian: 0x00 0x01
/// bytes 8-15  uint64 offset of the root group
/// data block: uint64 size, then size bytes
/// group:      uint64 child count n, then n uint64 children; a child with the top bit set is a
///             data block at (child & ~top bit), 0x8000000000000000 alone is an empty data block;
///             a child without it is a group at that offset, 0 an empty group
/// ```
///
/// All integers are little-endian. The writer lays blocks out children first (a group is written
/// after everything it points to), as the reference library's frozen files are.
#pragma once

#include <vdbhair/io/ByteReader.h>

#include <cstdint>
#include <cstring>
#include <deque>
#include <string>
#include <vector>

namespace vdbhair {
namespace ogawa {

constexpr std::uint64_t kDataBit = 0x8000000000000000ULL;  ///< marks a data child
constexpr std::uint64_t kEmptyGroup = 0;                   ///< a group without children
constexpr std::uint64_t kEmptyData = kDataBit;             ///< a data block of 0 bytes

/// @brief Builds an Ogawa file bottom-up: every block is added before the group that holds it,
/// so that each child's offset is known when its parent is laid out. Data may be borrowed from
/// the caller (no copy of large arrays) or owned.
class Writer
{
public:
    /// A node added so far: a data block or a group (opaque; pass it to addGroup()).
    struct Node { std::uint64_t index; bool isData; };
    /// Pieces of a data block: (pointer, byte count) each.
    using Pieces = std::vector<std::pair<const void*, std::uint64_t>>;

    /// @brief A data block made of @a pieces concatenated; each piece's memory must stay valid
    /// until write(). An empty block costs nothing (Ogawa's empty-data marker).
    Node addData(Pieces pieces);
    /// @brief A data block holding a copy of @a bytes.
    Node addData(std::string bytes);
    /// @brief A group of @a children, in order. A group without children is Ogawa's empty group.
    Node addGroup(const std::vector<Node>& children);

    /// @brief Write the file with the last group added as the root.
    /// @param append called with consecutive pieces of the file (e.g. AtomicFileWriter::append)
    template<typename AppendT>
    void write(AppendT&& append) const;

    /// The size in bytes write() produces.
    std::uint64_t fileSize() const;

private:
    struct Block { Pieces pieces; std::uint64_t size = 0; };
    struct Group { std::vector<Node> children; };
    std::vector<Block> mData;
    std::deque<std::string> mOwned;  // a deque: its strings never move, so pieces may point into them
    std::vector<Group> mGroups;
    std::vector<Node> mOrder;  // blocks and groups in the order they are written

    /// Offsets of every block and group (0 for empty ones) and the file size.
    void layout(std::vector<std::uint64_t>& dataPos, std::vector<std::uint64_t>& groupPos,
                std::uint64_t& end) const;
    std::uint64_t childWord(const Node& n, const std::vector<std::uint64_t>& dataPos,
                            const std::vector<std::uint64_t>& groupPos) const;
};

/// @brief Read-only view of an Ogawa file's bytes with bounds-checked groups and data.
///
/// Every offset and count read from the file is checked against the file's size before it is
/// used, so no allocation is ever made from an unchecked number; errors are FormatError with the
/// file, the byte offset, the value and the rule.
class Reader
{
public:
    /// @throw FormatError (no "Ogawa" magic, unfinished file, unknown version, root out of range).
    Reader(const char* data, std::size_t size, std::string where);

    /// A group's child words as stored, read in place (no copy, so a group's size costs nothing).
    class Words
    {
    public:
        Words() = default;
        Words(const char* data, std::uint64_t count) : mData(data), mCount(count) {}
        std::uint64_t size() const { return mCount; }
        bool empty() const { return mCount == 0; }
        std::uint64_t operator[](std::uint64_t i) const
        {
            std::uint64_t v;
            std::memcpy(&v, mData + 8 * i, 8);
            return v;
        }
    private:
        const char* mData = nullptr;
        std::uint64_t mCount = 0;
    };
    /// A group: where it is and its children.
    struct Group { std::uint64_t pos = 0; Words children; };
    /// A data block: its bytes in the file.
    struct Data { std::uint64_t pos = 0; const char* bytes = nullptr; std::uint64_t size = 0; };

    std::uint64_t rootPos() const { return mRoot; }
    /// @brief The group at @a pos (0: the empty group, no children).
    /// @throw FormatError if it does not fit in the file.
    Group group(std::uint64_t pos, const std::string& what) const;
    /// @brief Child @a i of @a g as a group (its offset), checking that it is one.
    std::uint64_t childGroup(const Group& g, std::size_t i, const std::string& what) const;
    /// @brief Child @a i of @a g as a data block, checking that it is one and fits in the file.
    Data childData(const Group& g, std::size_t i, const std::string& what) const;

    const ByteReader& bytes() const { return mBytes; }
    [[noreturn]] void failAt(std::uint64_t pos, const std::string& msg) const
    {
        mBytes.failAt(std::size_t(pos), msg);
    }

private:
    ByteReader mBytes;
    std::uint64_t mRoot = 0;
};

/// @brief MurmurHash3_x64_128 with seed 0 (Austin Appleby's public-domain hash), the digest
/// Alembic stores in front of every sample (AbcCoreAbstract's ArraySample key).
void murmur3x64_128(const void* data, std::size_t size, std::uint64_t out[2]);

// ---------------------------------------------------------------------------------------------

template<typename AppendT>
void Writer::write(AppendT&& append) const
{
    std::vector<std::uint64_t> dataPos, groupPos;
    std::uint64_t end = 0;
    layout(dataPos, groupPos, end);
    // Header: magic, frozen, version 1, root group offset.
    char header[16] = {'O', 'g', 'a', 'w', 'a', char(0xff), 0, 1};
    const std::uint64_t root = mGroups.empty() ? 0 : groupPos.back();
    std::memcpy(header + 8, &root, 8);
    append(header, 16);
    std::vector<std::uint64_t> words;
    for (const Node& n : mOrder) {
        if (n.isData) {
            const Block& b = mData[n.index];
            append(&b.size, 8);
            for (const auto& piece : b.pieces) if (piece.second) append(piece.first, piece.second);
        } else {
            const Group& g = mGroups[n.index];
            words.assign(1, g.children.size());
            for (const Node& c : g.children) words.push_back(childWord(c, dataPos, groupPos));
            append(words.data(), words.size() * 8);
        }
    }
}

} // namespace ogawa

/// AbcCoreOgawa's encoding on top of the container (AbcFile.cc reads it, AbcWrite.cc writes it).
namespace abc {
/// Alembic's plain-old-data types (Util/PlainOldDataType.h) used here, and their sizes in bytes.
enum Pod : unsigned { kUint8 = 1, kInt8 = 2, kInt16 = 4, kUint32 = 5, kInt32 = 6, kFloat32 = 10, kFloat64 = 11, kNumPods = 14 };
constexpr unsigned kPodBytes[kNumPods] = {1, 1, 1, 2, 2, 4, 4, 8, 8, 2, 4, 8, 0, 0};
constexpr std::int32_t kOgawaFileVersion = 0;    ///< AbcCoreOgawa's ALEMBIC_OGAWA_FILE_VERSION
constexpr std::int32_t kLibraryVersion = 10812;  ///< the layout of Alembic 1.8.12
enum PropertyType : unsigned { kCompound = 0, kScalar = 1, kArray = 2 };
} // namespace abc
} // namespace vdbhair
