#include "IdList.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/io/FileUtil.h>

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <limits>

namespace vdbhair {

namespace {

/// Every token of @a path (white space or commas between, '#' comments), parsed by @a parse into
/// @a out; @a kind names a good token in messages.
template <typename T, typename Parse>
std::vector<T> readList(const std::string& path, std::size_t expected, const std::string& what, const char* function, const char* kind, const char* noun, Parse&& parse)
{
    const std::string where = std::string(function) + "(" + path + ")";
    requireRegularFile(path, where);
    const std::vector<char> bytes = readFileBytes(path, where);
    const std::string one = what.substr(0, what.size() - (what.size() > 1 && what.back() == 's' ? 1 : 0));
    std::vector<T> out;
    std::size_t line = 1, i = 0;
    const std::size_t n = bytes.size();
    while (i < n) {
        const char c = bytes[i];
        if (c == '\n') { ++line; ++i; continue; }
        if (c == ' ' || c == '\t' || c == '\r' || c == ',') { ++i; continue; }
        if (c == '#') {
            while (i < n && bytes[i] != '\n') ++i;
            continue;
        }
        std::size_t j = i;
        while (j < n && bytes[j] != '\n' && bytes[j] != ' ' && bytes[j] != '\t' && bytes[j] != '\r' && bytes[j] != ',' && bytes[j] != '#') ++j;
        const std::string token(bytes.data() + i, j - i);
        T v;
        if (!parse(token, v)) throw FormatError(where + ": line " + std::to_string(line) + ": '" + token.substr(0, 40) + "' is not " + kind);
        if (expected > 0 && out.size() == expected) {
            throw ValueError(where + ": more than " + std::to_string(expected) + " " + noun + " for " + std::to_string(expected) + " " + what + ": one per " + one);
        }
        out.push_back(v);
        i = j;
    }
    if (expected > 0 && out.size() != expected) {
        throw ValueError(where + ": " + std::to_string(out.size()) + " " + noun + " for " + std::to_string(expected) + " " + what + ": one per " + one);
    }
    return out;
}

} // namespace

std::vector<std::int32_t> readIdList(const std::string& path, std::size_t expected, const std::string& what)
{
    return readList<std::int32_t>(path, expected, what, "readIdList", "a 32-bit integer id", "ids", [](const std::string& token, std::int32_t& v) {
        char* end = nullptr;
        errno = 0;
        const long long x = std::strtoll(token.c_str(), &end, 10);
        if (token.empty() || *end != '\0' || errno == ERANGE || x < std::numeric_limits<std::int32_t>::min() || x > std::numeric_limits<std::int32_t>::max()) return false;
        v = std::int32_t(x);
        return true;
    });
}

std::vector<double> readValueList(const std::string& path, std::size_t expected, const std::string& what)
{
    return readList<double>(path, expected, what, "readValueList", "a finite number", "values", [](const std::string& token, double& v) {
        char* end = nullptr;
        errno = 0;
        v = std::strtod(token.c_str(), &end);
        return !token.empty() && *end == '\0' && errno != ERANGE && std::isfinite(v);
    });
}

} // namespace vdbhair
