#include "TfxFile.h"

#include <vdbhair/io/ByteReader.h>
#include <vdbhair/io/FileUtil.h>
#include <vdbhair/io/MappedFile.h>
#include <vdbhair/io/TextScanner.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <limits>

namespace vdbhair {

namespace {

/// Shared by binary 3.0 and 4.x: @a nS strands of @a nV vertices of @a stride floats at @a posAt.
StrandSet readBinaryStrands(ByteReader& in, std::uint32_t nS, std::uint32_t nV, std::size_t stride,
                            std::uint64_t posAt, std::uint64_t uvAt, std::uint64_t thicknessAt,
                            const ReadOptions& opts)
{
    const std::string& where = in.where();
    const std::uint64_t total = std::uint64_t(nS) * nV;
    if (total > std::numeric_limits<std::uint32_t>::max()) {
        in.failAt(4, std::to_string(nS) + " strands of " + std::to_string(nV) + " vertices exceed 2^32-1 vertices");
    }
    // A strand of fewer than 2 vertices is never kept, and strands of 0 vertices take no bytes:
    // 2^32-1 of them would size the output and the loop by a count the file does not bound.
    if (nS > 0 && nV < 2) {
        in.failAt(8, std::to_string(nS) + " strands of " + std::to_string(nV) +
                         " vertices: every strand of a TressFX file has the same count, and a strand needs at least 2");
    }
    in.seek(posAt, "the vertex position offset");
    in.require(total, stride * 4, std::to_string(nS) + " strands of " + std::to_string(nV) + " vertices");
    const char* raw = in.current();  // the file's bytes, copied once below

    std::vector<Vec2f> uv;
    if (uvAt) {
        in.seek(uvAt, "the strand texcoord offset");
        uv.resize(nS);
        in.readArray(reinterpret_cast<float*>(uv.data()), 2 * std::uint64_t(nS), "strand texcoords");
    }
    std::vector<float> thickness;
    if (thicknessAt) {
        in.seek(thicknessAt, "the strand thickness offset");
        thickness.resize(nS);
        in.readArray(thickness.data(), nS, "strand thickness");
    }

    // Every strand has nV >= 2 vertices (checked above), so none is dropped: positions are copied
    // out of the file's bytes in one pass, and locations are built only for a non-finite vertex.
    StrandSet out;
    out.reserve(nS, total);
    out.positions.resize(total);
    out.offsets.resize(std::size_t(nS) + 1);
    InterruptPoll poll(opts.interrupter, where);
    const std::size_t vertexBytes = stride * 4;
    for (std::uint32_t i = 0; i < nS; ++i) {
        poll();
        const std::size_t first = std::size_t(i) * nV;
        Vec3f* dst = out.positions.data() + first;
        for (std::uint32_t k = 0; k < nV; ++k) std::memcpy(dst[k].asPointer(), raw + (first + k) * vertexBytes, 12);
        if (!allFinite(dst, 3 * std::size_t(nV))) {
            for (std::uint32_t k = 0; k < nV; ++k) {
                checkFinite(dst[k], first + k, where, "at byte " + std::to_string(posAt + (first + k) * vertexBytes));
            }
        }
        out.offsets[i + 1] = std::uint32_t(first + nV);
    }
    if (!uv.empty()) out.rootUV = std::move(uv);
    if (!thickness.empty()) {
        out.thickness.resize(total);
        for (std::uint32_t i = 0; i < nS; ++i) {
            std::fill_n(out.thickness.begin() + std::ptrdiff_t(std::size_t(i) * nV), nV, thickness[i]);
        }
    }
    return out;
}

StrandSet readAscii(const MappedFile& file, const std::string& where,
                    const ReadOptions& opts, ReadReport* report)
{
    TextScanner text(file.data(), file.size(), where);
    StrandSet out;
    ShortStrandFilter filter(opts, report, where);
    InterruptPoll poll(opts.interrupter, where);
    std::int64_t declared = -1;
    std::size_t strandsSeen = 0;
    std::vector<std::string_view> tok;
    while (text.nextLine(tok)) {
        poll();
        if (tok.empty() || tok[0][0] == '#') continue;
        const std::string_view key = tok[0];
        if (key == "strand") {
            // strand i numVerts k texcoord u v
            if (tok.size() < 4 || tok[2] != "numVerts") text.fail("expected 'strand <i> numVerts <k> ...'");
            if (declared < 0) text.fail("a strand appears before 'numStrands'");
            if (std::int64_t(strandsSeen) >= declared) {
                text.fail("more strands than the " + std::to_string(declared) + " declared by numStrands");
            }
            const std::int64_t k = text.toInt(tok[3], "numVerts");
            if (k < 0) text.fail("numVerts " + std::to_string(k) + " is negative");
            // Each vertex needs a line of at least 6 bytes ("0 0 0\n").
            if (std::uint64_t(k) > text.remainingBytes() / 6) {
                text.fail("strand declares " + std::to_string(k) + " vertices but only " +
                          std::to_string(text.remainingBytes()) + " bytes remain");
            }
            Vec2f uv(0.f);
            if (tok.size() >= 7 && tok[4] == "texcoord") uv = Vec2f(text.toFloat(tok[5], "u"), text.toFloat(tok[6], "v"));
            const std::size_t headerLine = text.line();
            const std::size_t first = out.positions.size();
            for (std::int64_t j = 0; j < k; ++j) {
                poll();
                if (!text.nextLine(tok, /*commas=*/true)) text.fail("file ends inside strand " + std::to_string(strandsSeen) + " (" + std::to_string(j) + " of " + std::to_string(k) + " vertices read)");
                if (tok.size() < 3) text.fail("a vertex line needs 3 numbers");
                const Vec3f p(text.toFloat(tok[0], "x"), text.toFloat(tok[1], "y"), text.toFloat(tok[2], "z"));
                checkFinite(p, out.positions.size(), where, "line " + std::to_string(text.line()));
                out.positions.push_back(p);
            }
            if (filter.keep(strandsSeen, std::size_t(k), "line " + std::to_string(headerLine))) {
                out.offsets.push_back(std::uint32_t(out.positions.size()));
                out.rootUV.push_back(uv);
            } else {
                out.positions.resize(first);
            }
            ++strandsSeen;
        } else if (key == "numStrands") {
            if (tok.size() < 2) text.fail("numStrands needs a value");
            declared = text.toInt(tok[1], "numStrands");
            if (declared < 0) text.fail("numStrands " + std::to_string(declared) + " is negative");
            if (std::uint64_t(declared) > text.remainingBytes() / 8) {
                text.fail("numStrands " + std::to_string(declared) + " cannot fit in the " +
                          std::to_string(text.remainingBytes()) + " bytes that remain");
            }
            out.offsets.reserve(std::size_t(declared) + 1);
        } else if (key == "version") {
            if (tok.size() < 2) text.fail("version needs a value");
            const float v = text.toFloat(tok[1], "version");
            if (v != 1.f && v != 2.f) throw UnsupportedError(where + ": line " + std::to_string(text.line()) + ": ASCII version " + std::string(tok[1]) + " is not supported (1.0 and 2.0 are)");
        } else if (key == "scale" || key == "rotation" || key == "translation") {
            const float identity = (key == "scale") ? 1.f : 0.f;
            for (std::size_t j = 1; j < tok.size(); ++j) {
                if (text.toFloat(tok[j], std::string(key).c_str()) != identity) {
                    throw UnsupportedError(where + ": line " + std::to_string(text.line()) + ": a non-identity '" +
                                           std::string(key) + "' is not supported; bake the transform into the vertices");
                }
            }
        }
        // Other header keys (bothEndsImmovable, maxNumVerticesInStrand, ...) describe simulation.
    }
    if (declared < 0) text.fail("no 'numStrands' line: not a TressFX ASCII file");
    if (std::int64_t(strandsSeen) != declared) {
        text.fail("numStrands declares " + std::to_string(declared) + " strands but the file has " + std::to_string(strandsSeen));
    }
    filter.finish();
    return out;
}

} // namespace

StrandSet readTfx(const std::string& path, const ReadOptions& opts, ReadReport* report)
{
    const std::string where = "readTfx(" + path + ")";
    const MappedFile file(path, where, opts.interrupter);
    ByteReader in(file.data(), file.size(), where);
    if (file.size() >= 4 && std::isalpha(static_cast<unsigned char>(file.data()[0]))) {
        return readAscii(file, where, opts, report);
    }
    const float version = in.read<float>("version");
    if (version == 3.f) {
        if (file.size() < 296) in.failAt(0, "the file has " + std::to_string(file.size()) + " bytes, shorter than the 296-byte TressFX 3 header");
        const std::uint32_t nS = in.read<std::uint32_t>("strand count");
        const std::uint32_t nV = in.read<std::uint32_t>("vertices per strand");
        in.seek(144, "header");
        const std::uint32_t posAt = in.read<std::uint32_t>("vertex offset");
        const std::uint32_t thicknessAt = in.read<std::uint32_t>("thickness offset");
        const std::uint32_t uvAt = in.read<std::uint32_t>("texcoord offset");
        return readBinaryStrands(in, nS, nV, 3, posAt ? posAt : 296, uvAt, thicknessAt, opts);
    }
    if (version >= 4.f && version < 5.f) {
        if (file.size() < 160) in.failAt(0, "the file has " + std::to_string(file.size()) + " bytes, shorter than the 160-byte TressFX 4 header");
        const std::uint32_t nS = in.read<std::uint32_t>("strand count");
        const std::uint32_t nV = in.read<std::uint32_t>("vertices per strand");
        const std::uint32_t posAt = in.read<std::uint32_t>("position offset");
        const std::uint32_t uvAt = in.read<std::uint32_t>("strand UV offset");
        in.read<std::uint32_t>("vertex UV offset");
        const std::uint32_t thicknessAt = in.read<std::uint32_t>("strand thickness offset");
        return readBinaryStrands(in, nS, nV, 4, posAt ? posAt : 160, uvAt, thicknessAt, opts);
    }
    throw UnsupportedError(where + ": at byte 0: version " + std::to_string(version) +
                           " is not supported; vdbhair reads TressFX binary 3.0 and 4.x and ASCII 1.0/2.0");
}

} // namespace vdbhair
