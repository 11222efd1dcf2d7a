/// @file ByteReader.h
/// @brief Bounds-checked little-endian reading from a file's bytes. Every read checks that the
/// bytes exist before it copies or allocates, and a failure names the file, the byte offset and
/// the rule: `readHair(a.hair): at byte 128: strand 12 declares 70000 points but only 1200 remain`.
#pragma once

#include <vdbhair/Exceptions.h>

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <type_traits>
#include <vector>

namespace vdbhair {

static_assert(sizeof(float) == 4, "vdbhair's binary readers assume 32-bit IEEE floats");

class ByteReader
{
public:
    /// @param where message prefix, e.g. "readHair(a.hair)"
    ByteReader(const std::vector<char>& bytes, std::string where)
        : ByteReader(bytes.data(), bytes.size(), std::move(where)) {}
    /// @param data, size the bytes (e.g. a MappedFile's), which must outlive the reader
    ByteReader(const char* data, std::size_t size, std::string where)
        : mData(data), mSize(size), mWhere(std::move(where)) {}

    std::size_t offset() const { return mOffset; }
    std::size_t size() const { return mSize; }
    std::size_t remaining() const { return mSize - mOffset; }
    const std::string& where() const { return mWhere; }

    /// @brief Fail unless @a count items of @a itemSize bytes remain (no overflow possible).
    void require(std::uint64_t count, std::size_t itemSize, const std::string& what) const
    {
        if (itemSize != 0 && count > remaining() / itemSize) {
            fail(what + " needs " + std::to_string(count) + " x " + std::to_string(itemSize) +
                 " bytes but only " + std::to_string(remaining()) + " remain in the file");
        }
    }

    /// @brief Move to absolute byte @a off (which may be the end of the file).
    void seek(std::uint64_t off, const std::string& what)
    {
        if (off > mSize) {
            fail(what + " points to byte " + std::to_string(off) + ", past the end of the " +
                 std::to_string(mSize) + "-byte file");
        }
        mOffset = std::size_t(off);
    }

    /// @brief Fail unless @a count items of @a itemSize bytes remain, with the message built only
    /// on failure (for per-item loops: `what` is a string literal, no allocation).
    void require(std::uint64_t count, std::size_t itemSize, const char* what) const
    {
        if (itemSize != 0 && count > remaining() / itemSize) require(count, itemSize, std::string(what));
    }

    template<typename T>
    T read(const char* what)
    {
        static_assert(std::is_trivially_copyable<T>::value, "plain data only");
        require(1, sizeof(T), what);
        T value;
        std::memcpy(&value, mData + mOffset, sizeof(T));
        mOffset += sizeof(T);
        return value;
    }

    template<typename T>
    void readArray(T* dst, std::uint64_t count, const char* what)
    {
        static_assert(std::is_trivially_copyable<T>::value, "plain data only");
        require(count, sizeof(T), what);
        if (count) std::memcpy(dst, mData + mOffset, std::size_t(count) * sizeof(T));
        mOffset += std::size_t(count) * sizeof(T);
    }

    void skip(std::uint64_t bytes, const char* what)
    {
        require(bytes, 1, what);
        mOffset += std::size_t(bytes);
    }

    const char* current() const { return mData + mOffset; }

    [[noreturn]] void fail(const std::string& msg) const { failAt(mOffset, msg); }
    [[noreturn]] void failAt(std::size_t off, const std::string& msg) const
    {
        throw FormatError(mWhere + ": at byte " + std::to_string(off) + ": " + msg);
    }

private:
    const char* mData;
    std::size_t mSize;
    std::string mWhere;
    std::size_t mOffset = 0;
};

/// @brief Whether the @a count floats at @a v (any alignment) are all finite: branch-free over the
/// whole array, so that readers test a strand or an array at once and look for the culprit (to
/// name it) only on failure.
inline bool allFinite(const void* v, std::size_t count)
{
    const char* bytes = static_cast<const char*>(v);
    std::uint32_t bad = 0;
    for (std::size_t i = 0; i < count; ++i) {
        std::uint32_t bits;
        std::memcpy(&bits, bytes + 4 * i, 4);
        bad |= std::uint32_t((bits & 0x7f800000u) == 0x7f800000u);  // all exponent bits: inf or NaN
    }
    return bad == 0;
}

} // namespace vdbhair
