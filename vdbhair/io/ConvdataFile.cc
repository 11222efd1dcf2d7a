#include "ConvdataFile.h"

#include <vdbhair/io/ByteReader.h>
#include <vdbhair/io/FileUtil.h>

#include <cctype>
#include <charconv>
#include <cstring>
#include <limits>

namespace vdbhair {

StrandSet readConvdata(const std::string& path, const ReadOptions& opts, ReadReport* report)
{
    const std::string where = "readConvdata(" + path + ")";
    const std::vector<char> bytes = readFileBytes(path, where, opts.interrupter);
    ByteReader in(bytes, where);
    if (bytes.size() < 10 || std::memcmp(bytes.data(), "\x93NUMPY", 6) != 0) {
        in.fail("not a NumPy .npy file: the first 6 bytes must be \\x93NUMPY");
    }
    in.skip(6, "magic");
    const std::uint8_t major = in.read<std::uint8_t>("major version");
    in.read<std::uint8_t>("minor version");
    std::uint32_t headerLen = 0;
    if (major == 1) headerLen = in.read<std::uint16_t>("header length");
    else if (major == 2 || major == 3) headerLen = in.read<std::uint32_t>("header length");
    else throw UnsupportedError(where + ": at byte 6: .npy version " + std::to_string(major) + " is not supported (1 to 3 are)");
    in.require(headerLen, 1, "the .npy header");
    const std::string header(in.current(), headerLen);
    in.skip(headerLen, "header");
    const std::size_t dataAt = in.offset();

    auto valueOf = [&](const std::string& key) -> std::string {
        const std::size_t k = header.find("'" + key + "'");
        if (k == std::string::npos) in.failAt(10, "the .npy header has no '" + key + "' entry");
        const std::size_t colon = header.find(':', k);
        std::size_t b = colon + 1;
        while (b < header.size() && header[b] == ' ') ++b;
        std::size_t e = b;
        if (b < header.size() && header[b] == '(') {
            e = header.find(')', b);
            if (e == std::string::npos) in.failAt(10, "the .npy header's '" + key + "' entry has no closing ')'");
            ++e;
        }
        else while (e < header.size() && header[e] != ',' && header[e] != '}') ++e;
        return header.substr(b, e - b);
    };
    const std::string descr = valueOf("descr");
    if (descr != "'<f4'") throw UnsupportedError(where + ": dtype " + descr + " is not supported; HairNet convdata is little-endian float32 ('<f4')");
    if (valueOf("fortran_order") != "False") throw UnsupportedError(where + ": Fortran-ordered arrays are not supported");
    const std::string shapeStr = valueOf("shape");
    std::vector<std::uint64_t> shape;
    for (std::size_t i = 1; i < shapeStr.size();) {
        while (i < shapeStr.size() && (shapeStr[i] == ' ' || shapeStr[i] == ',')) ++i;
        if (i >= shapeStr.size() || shapeStr[i] == ')') break;
        std::size_t e = i;
        while (e < shapeStr.size() && std::isdigit(static_cast<unsigned char>(shapeStr[e]))) ++e;
        if (e == i) in.failAt(10, "cannot read the shape " + shapeStr);
        std::uint64_t dim = 0;
        const auto [end, ec] = std::from_chars(shapeStr.data() + i, shapeStr.data() + e, dim);
        if (ec != std::errc() || end != shapeStr.data() + e) {
            in.failAt(10, "shape " + shapeStr + " has dimension " + shapeStr.substr(i, e - i) + ", beyond 2^64-1");
        }
        shape.push_back(dim);
        i = e;
    }
    if (shape.size() != 3 || shape[0] % 4 != 0 || shape[0] == 0) {
        throw UnsupportedError(where + ": shape " + shapeStr + " is not (4·points, rows, columns)");
    }
    const std::uint64_t nP = shape[0] / 4, rows = shape[1], cols = shape[2];
    // Each product is checked before it is formed (shape[0] * rows * cols can wrap 2^64).
    if (rows && cols > std::numeric_limits<std::uint32_t>::max() / rows) in.fail("shape " + shapeStr + " is too large");
    const std::uint64_t slots = rows * cols;
    if (slots && shape[0] > std::numeric_limits<std::uint64_t>::max() / 4 / slots) {
        in.fail("the array of shape " + shapeStr + " needs " + std::to_string(shape[0]) + " x " + std::to_string(slots) +
                " floats, more than 2^64 bytes");
    }
    in.require(shape[0] * slots, 4, "the array of shape " + shapeStr);
    std::vector<float> data(std::size_t(shape[0] * slots));
    in.readArray(data.data(), shape[0] * slots, "array data");
    if (in.remaining() && report) report->warnings.push_back(where + ": " + std::to_string(in.remaining()) + " bytes after the array were ignored");

    StrandSet out;
    ShortStrandFilter filter(opts, report, where);
    if (slots == 0) {
        // No strand slots: the array holds no floats, so nothing bounds the point count by the
        // file's size; nothing is allocated from it.
        if (report) report->warnings.push_back(where + ": shape " + shapeStr + " has no strand slots (rows x columns = 0)");
        filter.finish();
        return out;
    }
    std::size_t empty = 0;
    std::vector<Vec3f> pts(nP);  // nP x slots floats were read above, so nP is bounded by the file
    InterruptPoll poll(opts.interrupter, where);
    for (std::uint64_t s = 0; s < slots; ++s) {
        poll();
        bool allZero = true;
        for (std::uint64_t i = 0; i < nP; ++i) {
            for (int c = 0; c < 3; ++c) {
                const float v = data[std::size_t((i * 4 + std::uint64_t(c)) * slots + s)];
                pts[i][c] = v;
                allZero = allZero && v == 0.f;
            }
        }
        if (allZero) { ++empty; continue; }
        for (std::uint64_t i = 0; i < nP; ++i) {
            checkFinite(pts[i], out.positions.size() + i, where, "at byte " + std::to_string(dataAt + 4 * ((i * 4) * slots + s)));
        }
        if (filter.keep(std::size_t(s), std::size_t(nP), "slot " + std::to_string(s))) out.addStrand(pts);
    }
    if (empty && report) report->warnings.push_back(where + ": skipped " + std::to_string(empty) + " empty (all-zero) strand slots of " + std::to_string(slots));
    filter.finish();
    return out;
}

} // namespace vdbhair
