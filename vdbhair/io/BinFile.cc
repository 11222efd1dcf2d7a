#include "BinFile.h"

#include <vdbhair/Memory.h>
#include <vdbhair/io/ByteReader.h>
#include <vdbhair/io/FileUtil.h>
#include <vdbhair/io/MappedFile.h>

#include <cstring>
#include <limits>

namespace vdbhair {

StrandSet readBin(const std::string& path, const ReadOptions& opts, ReadReport* report)
{
    const std::string where = "readBin(" + path + ")";
    const MappedFile file(path, where, opts.interrupter);
    ByteReader in(file.data(), file.size(), where);
    constexpr std::size_t kVertexBytes = 7 * 4;
    const std::int32_t nS = in.read<std::int32_t>("strand count");
    if (nS < 0) in.failAt(0, "strand count " + std::to_string(nS) + " is negative");
    in.require(std::uint64_t(nS), 4, "the declared " + std::to_string(nS) + " strands");

    StrandSet out;
    out.offsets.reserve(std::size_t(nS) + 1);
    reserveHugePages(out.positions, (in.remaining() - 4 * std::size_t(nS)) / kVertexBytes);  // bounded by the file size
    ShortStrandFilter filter(opts, report, where);
    InterruptPoll poll(opts.interrupter, where);
    for (std::int32_t i = 0; i < nS; ++i) {
        poll();
        const std::size_t at = in.offset();
        const std::int32_t nV = in.read<std::int32_t>("vertex count");
        if (nV < 0) in.failAt(at, "strand " + std::to_string(i) + " declares " + std::to_string(nV) + " vertices; counts must not be negative");
        if (std::uint64_t(nV) > in.remaining() / kVertexBytes) {
            in.failAt(at, "strand " + std::to_string(i) + " declares " + std::to_string(nV) +
                              " vertices (" + std::to_string(kVertexBytes * std::uint64_t(nV)) +
                              " bytes) but only " + std::to_string(in.remaining()) + " bytes remain");
        }
        // Each vertex is x, y, z and four more floats: positions are copied out of the file's
        // bytes in one pass, and the location of a non-finite one is built only if there is one.
        const std::size_t first = out.positions.size(), posAt = in.offset();
        const char* src = in.current();
        in.skip(kVertexBytes * std::uint64_t(nV), "vertices");
        out.positions.resize(first + std::size_t(nV));
        Vec3f* dst = out.positions.data() + first;
        for (std::int32_t k = 0; k < nV; ++k) std::memcpy(dst[k].asPointer(), src + kVertexBytes * std::size_t(k), 12);
        if (!allFinite(dst, 3 * std::size_t(nV))) {
            for (std::int32_t k = 0; k < nV; ++k) {
                checkFinite(dst[k], first + std::size_t(k), where, "at byte " + std::to_string(posAt + kVertexBytes * std::size_t(k)));
            }
        }
        if (filter.keep(std::size_t(i), std::size_t(nV), "at byte " + std::to_string(at))) {
            if (out.positions.size() > std::numeric_limits<std::uint32_t>::max()) in.fail("more than 2^32-1 vertices");
            out.offsets.push_back(std::uint32_t(out.positions.size()));
        } else {
            out.positions.resize(first);
        }
    }
    if (in.remaining() && report) {
        report->warnings.push_back(where + ": " + std::to_string(in.remaining()) +
                                   " bytes after the last strand were ignored");
    }
    filter.finish();
    return out;
}

} // namespace vdbhair
