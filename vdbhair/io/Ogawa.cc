#include "Ogawa.h"

#include <vdbhair/Exceptions.h>

namespace vdbhair {
namespace ogawa {

// ---- writing ----------------------------------------------------------------------------------

Writer::Node Writer::addData(Pieces pieces)
{
    Block b;
    for (const auto& p : pieces) b.size += p.second;
    b.pieces = std::move(pieces);
    mData.push_back(std::move(b));
    const Node n{mData.size() - 1, true};
    if (mData.back().size != 0) mOrder.push_back(n);
    return n;
}

Writer::Node Writer::addData(std::string bytes)
{
    mOwned.push_back(std::move(bytes));
    return addData(Pieces{{mOwned.back().data(), mOwned.back().size()}});
}

Writer::Node Writer::addGroup(const std::vector<Node>& children)
{
    mGroups.push_back(Group{children});
    const Node n{mGroups.size() - 1, false};
    if (!children.empty()) mOrder.push_back(n);
    return n;
}

void Writer::layout(std::vector<std::uint64_t>& dataPos, std::vector<std::uint64_t>& groupPos,
                    std::uint64_t& end) const
{
    dataPos.assign(mData.size(), 0);
    groupPos.assign(mGroups.size(), 0);
    end = 16;
    for (const Node& n : mOrder) {
        if (n.isData) {
            dataPos[n.index] = end;
            end += 8 + mData[n.index].size;
        } else {
            groupPos[n.index] = end;
            end += 8 + 8 * std::uint64_t(mGroups[n.index].children.size());
        }
    }
}

std::uint64_t Writer::childWord(const Node& n, const std::vector<std::uint64_t>& dataPos,
                                const std::vector<std::uint64_t>& groupPos) const
{
    if (n.isData) return mData[n.index].size == 0 ? kEmptyData : (dataPos[n.index] | kDataBit);
    return groupPos[n.index];  // 0 for an empty group
}

std::uint64_t Writer::fileSize() const
{
    std::vector<std::uint64_t> dataPos, groupPos;
    std::uint64_t end = 0;
    layout(dataPos, groupPos, end);
    return end;
}

// ---- reading ----------------------------------------------------------------------------------

Reader::Reader(const char* data, std::size_t size, std::string where)
    : mBytes(data, size, std::move(where))
{
    if (size < 16 || std::memcmp(data, "Ogawa", 5) != 0) {
        mBytes.failAt(0, "no \"Ogawa\" magic in the first 5 bytes; an Alembic archive in the Ogawa "
                         "container starts with it (HDF5 Alembic archives are not read)");
    }
    if (static_cast<unsigned char>(data[5]) != 0xff) {
        mBytes.failAt(5, "frozen byte is " + std::to_string(static_cast<unsigned char>(data[5])) +
                         ", not 255: the writer did not finish the file");
    }
    const unsigned version = (unsigned(static_cast<unsigned char>(data[6])) << 8) |
                             static_cast<unsigned char>(data[7]);
    if (version != 1) {
        mBytes.failAt(6, "Ogawa version " + std::to_string(version) + "; only version 1 is read");
    }
    std::memcpy(&mRoot, data + 8, 8);
    if (mRoot < 16 || mRoot > size - 8) {
        mBytes.failAt(8, "root group offset " + std::to_string(mRoot) + " lies outside the " +
                         std::to_string(size) + "-byte file's blocks (16 to size - 8)");
    }
}

Reader::Group Reader::group(std::uint64_t pos, const std::string& what) const
{
    Group g;
    g.pos = pos;
    if (pos == kEmptyGroup) return g;
    const std::uint64_t size = mBytes.size();
    if (pos < 16 || pos > size - 8) {
        failAt(pos, what + ": group offset " + std::to_string(pos) + " lies outside the " +
                        std::to_string(size) + "-byte file");
    }
    std::uint64_t count = 0;
    std::memcpy(&count, mBytes.current() - mBytes.offset() + pos, 8);
    if (count > (size - pos - 8) / 8) {
        failAt(pos, what + ": group declares " + std::to_string(count) + " children but only " +
                        std::to_string((size - pos - 8) / 8) + " fit in the rest of the file");
    }
    g.children = Words(mBytes.current() - mBytes.offset() + pos + 8, count);
    return g;
}

std::uint64_t Reader::childGroup(const Group& g, std::size_t i, const std::string& what) const
{
    if (i >= g.children.size()) {
        failAt(g.pos, what + ": group has " + std::to_string(g.children.size()) +
                          " children, child " + std::to_string(i) + " is missing");
    }
    const std::uint64_t word = g.children[i];
    if (word & kDataBit) {
        failAt(g.pos + 8 + 8 * i, what + ": child " + std::to_string(i) + " is a data block (" +
                                      std::to_string(word & ~kDataBit) + "), a group was expected");
    }
    if (word != kEmptyGroup && (word < 16 || word > mBytes.size() - 8)) {
        failAt(g.pos + 8 + 8 * i, what + ": child group offset " + std::to_string(word) +
                                      " lies outside the " + std::to_string(mBytes.size()) + "-byte file");
    }
    return word;
}

Reader::Data Reader::childData(const Group& g, std::size_t i, const std::string& what) const
{
    if (i >= g.children.size()) {
        failAt(g.pos, what + ": group has " + std::to_string(g.children.size()) +
                          " children, child " + std::to_string(i) + " is missing");
    }
    const std::uint64_t word = g.children[i];
    const std::uint64_t at = g.pos + 8 + 8 * i;
    if (!(word & kDataBit)) {
        failAt(at, what + ": child " + std::to_string(i) + " is a group (" + std::to_string(word) +
                       "), a data block was expected");
    }
    Data d;
    d.pos = word & ~kDataBit;
    if (d.pos == 0) return d;  // the empty data block
    const std::uint64_t size = mBytes.size();
    if (d.pos < 16 || d.pos > size - 8) {
        failAt(at, what + ": data offset " + std::to_string(d.pos) + " lies outside the " +
                       std::to_string(size) + "-byte file");
    }
    const char* base = mBytes.current() - mBytes.offset();
    std::memcpy(&d.size, base + d.pos, 8);
    if (d.size > size - d.pos - 8) {
        failAt(d.pos, what + ": data block declares " + std::to_string(d.size) + " bytes but only " +
                          std::to_string(size - d.pos - 8) + " remain in the file");
    }
    d.bytes = base + d.pos + 8;
    return d;
}

// ---- MurmurHash3_x64_128 ----------------------------------------------------------------------

namespace {
inline std::uint64_t rotl64(std::uint64_t x, int r) { return (x << r) | (x >> (64 - r)); }
inline std::uint64_t fmix64(std::uint64_t k)
{
    k ^= k >> 33;
    k *= 0xff51afd7ed558ccdULL;
    k ^= k >> 33;
    k *= 0xc4ceb9fe1a85ec53ULL;
    k ^= k >> 33;
    return k;
}
} // namespace

void murmur3x64_128(const void* key, std::size_t len, std::uint64_t out[2])
{
    const auto* data = static_cast<const unsigned char*>(key);
    const std::size_t nblocks = len / 16;
    std::uint64_t h1 = 0, h2 = 0;
    const std::uint64_t c1 = 0x87c37b91114253d5ULL, c2 = 0x4cf5ad432745937fULL;
    for (std::size_t i = 0; i < nblocks; ++i) {
        std::uint64_t k1, k2;
        std::memcpy(&k1, data + 16 * i, 8);
        std::memcpy(&k2, data + 16 * i + 8, 8);
        k1 *= c1; k1 = rotl64(k1, 31); k1 *= c2; h1 ^= k1;
        h1 = rotl64(h1, 27); h1 += h2; h1 = h1 * 5 + 0x52dce729;
        k2 *= c2; k2 = rotl64(k2, 33); k2 *= c1; h2 ^= k2;
        h2 = rotl64(h2, 31); h2 += h1; h2 = h2 * 5 + 0x38495ab5;
    }
    const unsigned char* tail = data + nblocks * 16;
    std::uint64_t k1 = 0, k2 = 0;
    const std::size_t rest = len & 15;
    for (std::size_t i = rest; i > 8; --i) k2 ^= std::uint64_t(tail[i - 1]) << (8 * (i - 9));
    if (rest > 8) { k2 *= c2; k2 = rotl64(k2, 33); k2 *= c1; h2 ^= k2; }
    for (std::size_t i = rest < 8 ? rest : 8; i > 0; --i) k1 ^= std::uint64_t(tail[i - 1]) << (8 * (i - 1));
    if (rest > 0) { k1 *= c1; k1 = rotl64(k1, 31); k1 *= c2; h1 ^= k1; }
    h1 ^= len; h2 ^= len;
    h1 += h2; h2 += h1;
    h1 = fmix64(h1); h2 = fmix64(h2);
    h1 += h2; h2 += h1;
    out[0] = h1;
    out[1] = h2;
}

} // namespace ogawa
} // namespace vdbhair
