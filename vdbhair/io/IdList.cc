#include "IdList.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/io/FileUtil.h>

#include <cerrno>
#include <cstdlib>
#include <limits>

namespace vdbhair {

std::vector<std::int32_t> readIdList(const std::string& path, std::size_t expected, const std::string& what)
{
    const std::string where = "readIdList(" + path + ")";
    requireRegularFile(path, where);
    const std::vector<char> bytes = readFileBytes(path, where);
    std::vector<std::int32_t> ids;
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
        char* end = nullptr;
        errno = 0;
        const long long v = std::strtoll(token.c_str(), &end, 10);
        if (token.empty() || *end != '\0' || errno == ERANGE || v < std::numeric_limits<std::int32_t>::min() ||
            v > std::numeric_limits<std::int32_t>::max()) {
            throw FormatError(where + ": line " + std::to_string(line) + ": '" + token.substr(0, 40) + "' is not a 32-bit integer id");
        }
        if (expected > 0 && ids.size() == expected) {
            throw ValueError(where + ": more than " + std::to_string(expected) + " ids for " + std::to_string(expected) + " " + what + ": one per " +
                             what.substr(0, what.size() - (what.size() > 1 && what.back() == 's' ? 1 : 0)));
        }
        ids.push_back(std::int32_t(v));
        i = j;
    }
    if (expected > 0 && ids.size() != expected) {
        throw ValueError(where + ": " + std::to_string(ids.size()) + " ids for " + std::to_string(expected) + " " + what + ": one per " +
                         what.substr(0, what.size() - (what.size() > 1 && what.back() == 's' ? 1 : 0)));
    }
    return ids;
}

} // namespace vdbhair
