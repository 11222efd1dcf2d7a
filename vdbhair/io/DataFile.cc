#include "DataFile.h"

#include <vdbhair/io/ByteReader.h>
#include <vdbhair/io/FileUtil.h>
#include <vdbhair/io/MappedFile.h>

#include <cmath>
#include <limits>

namespace vdbhair {

StrandSet readData(const std::string& path, const ReadOptions& opts, ReadReport* report)
{
    const std::string where = "readData(" + path + ")";
    const MappedFile file(path, where, opts.interrupter);
    ByteReader in(file.data(), file.size(), where);
    const std::int32_t nS = in.read<std::int32_t>("strand count");
    if (nS < 0) in.failAt(0, "strand count " + std::to_string(nS) + " is negative");
    // Every strand needs at least its 4-byte vertex count.
    in.require(std::uint64_t(nS), 4, "the declared " + std::to_string(nS) + " strands");

    StrandSet out;
    // Bounded by the file size: what remains after the strands' vertex counts, 12 bytes a vertex.
    out.reserve(std::size_t(nS), (in.remaining() - 4 * std::size_t(nS)) / 12);
    ShortStrandFilter filter(opts, report, where);
    InterruptPoll poll(opts.interrupter, where);
    // Messages (and their locations) are built only for a strand that fails: building them for
    // every strand and vertex took three quarters of the time to read a 77 MB file.
    for (std::int32_t i = 0; i < nS; ++i) {
        poll();
        const std::size_t at = in.offset();
        const std::int32_t nV = in.read<std::int32_t>("vertex count");
        if (nV < 0) in.failAt(at, "strand " + std::to_string(i) + " declares " + std::to_string(nV) + " vertices; counts must not be negative");
        if (std::uint64_t(nV) > in.remaining() / 12) {
            in.failAt(at, "strand " + std::to_string(i) + " declares " + std::to_string(nV) +
                              " vertices (" + std::to_string(12ull * std::uint64_t(nV)) +
                              " bytes) but only " + std::to_string(in.remaining()) + " bytes remain");
        }
        const std::size_t first = out.positions.size();
        const std::size_t posAt = in.offset();
        out.positions.resize(first + std::size_t(nV));
        float* dst = reinterpret_cast<float*>(out.positions.data() + first);
        in.readArray(dst, 3 * std::uint64_t(nV), "vertices");
        if (!allFinite(dst, 3 * std::size_t(nV))) {
            for (std::int32_t k = 0; k < nV; ++k) {
                checkFinite(out.positions[first + k], first + k, where, "at byte " + std::to_string(posAt + 12 * std::size_t(k)));
            }
        }
        if (nV >= 2 || filter.keep(std::size_t(i), std::size_t(nV), "at byte " + std::to_string(at))) {
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

void writeData(const std::string& path, const StrandSet& strands)
{
    const std::string where = "writeData(" + path + ")";
    if (strands.numStrands() > std::size_t(std::numeric_limits<std::int32_t>::max())) {
        throw ValueError(where + ": " + std::to_string(strands.numStrands()) + " strands exceed the format's int32 count");
    }
    AtomicFileWriter out(path, where);
    out.appendValue(std::int32_t(strands.numStrands()));
    for (std::size_t i = 0; i < strands.numStrands(); ++i) {
        out.appendValue(std::int32_t(strands.size(i)));
        out.append(strands.data(i), 12 * strands.size(i));
    }
    out.commit();
}

} // namespace vdbhair
