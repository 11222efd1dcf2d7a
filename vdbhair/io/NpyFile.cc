#include "NpyFile.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/io/FileUtil.h>

#include <cstdint>
#include <cstring>

namespace vdbhair {

static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "writeNpy writes the host's floats as '<f4'");

std::string npyHeader(const std::vector<std::size_t>& shape)
{
    std::string dict = "{'descr': '<f4', 'fortran_order': False, 'shape': (";
    // "(96, 128, 128, 4)"; a one-axis shape keeps Python's tuple comma: "(5, )".
    for (std::size_t a = 0; a < shape.size(); ++a) dict += std::to_string(shape[a]) + (shape.size() == 1 || a + 1 < shape.size() ? ", " : "");
    dict += "), }";
    // Magic (6) + version (2) + length (2) + dict + padding + '\n', a multiple of 64 bytes.
    const std::size_t unpadded = 10 + dict.size() + 1;
    dict += std::string((64 - unpadded % 64) % 64, ' ') + "\n";
    const std::uint16_t len = std::uint16_t(dict.size());
    std::string header("\x93NUMPY\x01\x00", 8);
    header += char(len & 0xff);
    header += char(len >> 8);
    return header + dict;
}

void writeNpy(const std::string& path, const std::vector<std::size_t>& shape, const float* data)
{
    if (shape.empty()) throw ValueError("writeNpy(" + path + "): the shape is empty; arrays here have at least one axis");
    std::size_t count = 1;
    for (std::size_t n : shape) count *= n;
    std::string bytes = npyHeader(shape);
    const std::size_t start = bytes.size();
    bytes.resize(start + count * sizeof(float));
    if (count) std::memcpy(bytes.data() + start, data, count * sizeof(float));
    writeFileAtomic(path, bytes, "writeNpy(" + path + ")");
}

} // namespace vdbhair
