/// @file TextScanner.h
/// @brief Line-by-line tokenizing of text formats (OBJ, PLY headers, TressFX ASCII) with errors
/// that name the file and line: `readObj(a.obj): line 17: 'x1' is not a number (vertex y)`.
#pragma once

#include <vdbhair/Exceptions.h>

#include <charconv>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace vdbhair {

class TextScanner
{
public:
    /// @param begin offset of the first byte to scan (e.g. after a binary header)
    TextScanner(const std::vector<char>& bytes, std::string where, std::size_t begin = 0)
        : mData(bytes.data()), mSize(bytes.size()), mPos(begin), mWhere(std::move(where)) {}
    /// @param data, size the text (e.g. a MappedFile's bytes), which must outlive the scanner
    TextScanner(const char* data, std::size_t size, std::string where, std::size_t begin = 0)
        : mData(data), mSize(size), mPos(begin), mWhere(std::move(where)) {}

    /// @brief Split the next line into whitespace-separated tokens (with @a commas, commas separate
    /// them too: "x, y, z", as some TressFX exporters write vertices).
    /// @return false at the end of the text.
    bool nextLine(std::vector<std::string_view>& tokens, bool commas = false)
    {
        tokens.clear();
        if (mPos >= mSize) return false;
        ++mLine;
        std::size_t end = mPos;
        while (end < mSize && mData[end] != '\n') ++end;
        std::size_t i = mPos;
        while (i < end) {
            while (i < end && (isSpace(mData[i]) || (commas && mData[i] == ','))) ++i;
            const std::size_t start = i;
            while (i < end && !isSpace(mData[i]) && !(commas && mData[i] == ',')) ++i;
            if (i > start) tokens.emplace_back(mData + start, i - start);
        }
        mPos = (end < mSize) ? end + 1 : end;
        return true;
    }

    /// Continue numbering lines after @a line (for a scanner started mid-file).
    void setLine(std::size_t line) { mLine = line; }
    /// 1-based number of the line last returned.
    std::size_t line() const { return mLine; }
    /// Byte offset just after the line last returned.
    std::size_t offset() const { return mPos; }
    std::size_t remainingBytes() const { return mSize - mPos; }
    const std::string& where() const { return mWhere; }

    [[noreturn]] void fail(const std::string& msg) const
    {
        throw FormatError(mWhere + ": line " + std::to_string(mLine) + ": " + msg);
    }

    float toFloat(std::string_view s, const char* what) const
    {
        float v = 0.f;
        parse(s, v, what);
        return v;
    }
    double toDouble(std::string_view s, const char* what) const
    {
        double v = 0.0;
        parse(s, v, what);
        return v;
    }
    std::int64_t toInt(std::string_view s, const char* what) const
    {
        std::int64_t v = 0;
        parse(s, v, what);
        return v;
    }

private:
    static bool isSpace(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

    template<typename T>
    void parse(std::string_view s, T& v, const char* what) const
    {
        std::string_view t = s;
        if (!t.empty() && t[0] == '+') t.remove_prefix(1);
        const auto res = std::from_chars(t.data(), t.data() + t.size(), v);
        if (res.ec != std::errc() || res.ptr != t.data() + t.size()) {
            fail("'" + std::string(s) + "' is not a valid " +
                 (std::is_integral<T>::value ? "integer" : "number") + " (" + what + ")");
        }
    }

    const char* mData;
    std::size_t mSize, mPos;
    std::size_t mLine = 0;
    std::string mWhere;
};

} // namespace vdbhair
