#include "HairFile.h"

#include <vdbhair/Version.h>
#include <vdbhair/io/ByteReader.h>
#include <vdbhair/io/FileUtil.h>
#include <vdbhair/io/MappedFile.h>

#include <algorithm>
#include <cstring>

namespace vdbhair {

namespace {
enum : std::uint32_t { kSegments = 1, kPoints = 2, kThickness = 4, kTransparency = 8, kColors = 16 };
}

StrandSet readHair(const std::string& path, const ReadOptions& opts, ReadReport* report)
{
    const std::string where = "readHair(" + path + ")";
    const MappedFile file(path, where, opts.interrupter);
    ByteReader in(file.data(), file.size(), where);

    // Header
    if (file.size() < 4 || std::memcmp(file.data(), "HAIR", 4) != 0) {
        in.fail("not a cyHair file: the first 4 bytes must be \"HAIR\"");
    }
    if (file.size() < 128) {
        in.fail("the file has " + std::to_string(file.size()) +
                " bytes, shorter than the 128-byte cyHair header");
    }
    in.skip(4, "magic");
    const std::uint32_t hairCount = in.read<std::uint32_t>("strand count");
    const std::uint32_t pointCount = in.read<std::uint32_t>("point count");
    const std::uint32_t arrays = in.read<std::uint32_t>("array bits");
    const std::uint32_t defSegments = in.read<std::uint32_t>("default segments");
    StrandDefaults defaults;
    defaults.thickness = in.read<float>("default thickness");
    defaults.transparency = in.read<float>("default transparency");
    in.readArray(&defaults.color[0], 3, "default colour");
    in.seek(128, "header end");

    if (arrays & ~std::uint32_t(31)) {
        in.failAt(12, "array bits " + std::to_string(arrays) +
                          " set unknown bits; only 1, 2, 4, 8 and 16 are defined");
    }
    if (!(arrays & kPoints)) in.failAt(12, "the array bits have no points array (bit 2); there are no positions to read");

    // The file size must be exactly what the header describes (checked before allocating).
    const std::uint64_t nS = hairCount, nP = pointCount;
    std::uint64_t expected = 128;
    if (arrays & kSegments) expected += 2 * nS;
    expected += 12 * nP;
    if (arrays & kThickness) expected += 4 * nP;
    if (arrays & kTransparency) expected += 4 * nP;
    if (arrays & kColors) expected += 12 * nP;
    if (expected > file.size()) {
        in.failAt(4, "the header declares " + std::to_string(nS) + " strands and " +
                         std::to_string(nP) + " points, which need " + std::to_string(expected) +
                         " bytes, but the file has only " + std::to_string(file.size()));
    }
    if (expected < file.size() && report) {
        report->warnings.push_back(where + ": " + std::to_string(file.size() - expected) +
                                   " bytes after the arrays the header describes were ignored");
    }

    // Every strand has at least one point (segments + 1), so the point count bounds the strand
    // count: checked before anything is sized by it (2^32-1 strands of 0 points need no bytes).
    if (nS > nP) {
        in.failAt(4, "the header declares " + std::to_string(nS) + " strands but only " + std::to_string(nP) +
                         " points; every strand has at least one point");
    }
    if (!(arrays & kSegments) && defSegments < 65536u && nS * (std::uint64_t(defSegments) + 1) != nP) {
        in.failAt(8, "the strands' point counts add up to " + std::to_string(nS * (std::uint64_t(defSegments) + 1)) +
                         " but the header declares " + std::to_string(nP) + " points (no segments array: every strand has default segments " +
                         std::to_string(defSegments) + " + 1 points)");
    }

    // Points per strand
    std::vector<std::uint32_t> counts(nS);
    if (arrays & kSegments) {
        std::vector<std::uint16_t> seg(nS);
        in.readArray(seg.data(), nS, "segments array");
        for (std::size_t i = 0; i < nS; ++i) counts[i] = std::uint32_t(seg[i]) + 1;
    } else {
        if (defSegments >= 65536u) {
            in.failAt(16, "default segments " + std::to_string(defSegments) +
                              " exceeds the format's limit of 65535");
        }
        std::fill(counts.begin(), counts.end(), defSegments + 1);
    }
    std::uint64_t sum = 0;
    for (std::uint32_t c : counts) sum += c;
    if (sum != nP) {
        in.failAt(8, "the strands' point counts add up to " + std::to_string(sum) +
                         " but the header declares " + std::to_string(nP) + " points" +
                         ((arrays & kSegments) ? "" : " (no segments array: every strand has default segments " +
                                                          std::to_string(defSegments) + " + 1 points)"));
    }

    // Arrays: where each one lies (the size check above covers them all).
    const std::size_t pointsAt = in.offset();
    in.require(nP, 12, "points array");
    std::size_t at = pointsAt + 12 * nP;
    auto arrayAt = [&](std::uint32_t bit, std::size_t bytesPerPoint) -> const char* {
        if (!(arrays & bit)) return nullptr;
        const char* p = file.data() + at;
        at += bytesPerPoint * nP;
        return p;
    };
    const char* points = file.data() + pointsAt;
    const char* thickness = arrayAt(kThickness, 4);
    const char* transparency = arrayAt(kTransparency, 4);
    const char* colors = arrayAt(kColors, 12);

    // Strands: each array is copied once, from the file's bytes to the set, the positions checked
    // piece by piece as they are copied; only a file that fails the check or has strands to drop
    // is walked strand by strand (to name the culprit, to filter).
    StrandSet out;
    out.defaults = defaults;
    out.reserve(nS, nP);
    ShortStrandFilter filter(opts, report, where);
    const bool anyShort = std::any_of(counts.begin(), counts.end(), [](std::uint32_t c) { return c < 2; });
    auto copyRange = [&](auto& dst, const char* src, std::size_t bytesPerPoint, std::size_t v, std::size_t n) {
        if (!src || n == 0) return;  // (memcpy to an empty vector's null data is undefined, even of 0 bytes)
        const std::size_t old = dst.size();
        dst.resize(old + n);
        std::memcpy(reinterpret_cast<char*>(dst.data() + old), src + bytesPerPoint * v, bytesPerPoint * n);
    };
    // Positions in pieces that stay in the cache while they are copied and checked.
    bool finite = true;
    if (!anyShort) {
        constexpr std::size_t kPiece = std::size_t(1) << 14;
        for (std::size_t v = 0; v < nP && finite; v += kPiece) {
            const std::size_t n = std::min<std::size_t>(kPiece, nP - v);
            copyRange(out.positions, points, 12, v, n);
            finite = allFinite(out.positions.data() + v, 3 * n);
        }
    }
    if (finite && !anyShort) {
        copyRange(out.thickness, thickness, 4, 0, nP);
        copyRange(out.transparency, transparency, 4, 0, nP);
        copyRange(out.color, colors, 12, 0, nP);
        out.offsets.resize(nS + 1);
        for (std::size_t i = 0; i < nS; ++i) out.offsets[i + 1] = out.offsets[i] + counts[i];
    } else {
        out.positions.clear();
        finite = allFinite(points, 3 * nP);
        InterruptPoll poll(opts.interrupter, where);
        std::size_t v = 0;
        for (std::size_t i = 0; i < nS; ++i) {
            poll();
            const std::size_t n = counts[i];
            for (std::size_t k = v; !finite && k < v + n; ++k) {
                Vec3f p;
                std::memcpy(p.asPointer(), points + 12 * k, 12);
                checkFinite(p, k, where, "at byte " + std::to_string(pointsAt + 12 * k));
            }
            if (filter.keep(i, n, "strand at point " + std::to_string(v))) {
                copyRange(out.positions, points, 12, v, n);
                out.offsets.push_back(std::uint32_t(out.positions.size()));
                copyRange(out.thickness, thickness, 4, v, n);
                copyRange(out.transparency, transparency, 4, v, n);
                copyRange(out.color, colors, 12, v, n);
            }
            v += n;
        }
    }
    filter.finish();
    return out;
}

void writeHair(const std::string& path, const StrandSet& strands)
{
    const std::string where = "writeHair(" + path + ")";
    const std::size_t nS = strands.numStrands(), nP = strands.numVertices();
    if (nS > 0xffffffffu || nP > 0xffffffffu) throw ValueError(where + ": too many strands or points for 32-bit counts");
    bool uniform = nS > 0;
    for (std::size_t i = 0; i < nS; ++i) {
        if (strands.size(i) > 65536) {
            throw ValueError(where + ": strand " + std::to_string(i) + " has " +
                             std::to_string(strands.size(i)) +
                             " points; cyHair stores at most 65536 points per strand");
        }
        if (strands.size(i) != strands.size(0)) uniform = false;
    }
    std::uint32_t arrays = kPoints;
    if (!uniform) arrays |= kSegments;
    if (!strands.thickness.empty()) arrays |= kThickness;
    if (!strands.transparency.empty()) arrays |= kTransparency;
    if (!strands.color.empty()) arrays |= kColors;

    AtomicFileWriter out(path, where);
    auto put = [&out](const void* p, std::size_t n) { out.append(p, n); };
    auto putU32 = [&](std::uint32_t v) { put(&v, 4); };
    put("HAIR", 4);
    putU32(std::uint32_t(nS));
    putU32(std::uint32_t(nP));
    putU32(arrays);
    putU32(uniform ? std::uint32_t(strands.size(0) - 1) : 0u);
    put(&strands.defaults.thickness, 4);
    put(&strands.defaults.transparency, 4);
    put(strands.defaults.color.asPointer(), 12);
    char info[88] = {};
    std::snprintf(info, sizeof info, "%s", creatorString());
    put(info, 88);
    if (arrays & kSegments) {
        for (std::size_t i = 0; i < nS; ++i) {
            const std::uint16_t seg = std::uint16_t(strands.size(i) - 1);
            put(&seg, 2);
        }
    }
    if (nP) put(strands.positions.data(), 12 * nP);
    if (arrays & kThickness) put(strands.thickness.data(), 4 * nP);
    if (arrays & kTransparency) put(strands.transparency.data(), 4 * nP);
    if (arrays & kColors) put(strands.color.data(), 12 * nP);
    out.commit();
}

} // namespace vdbhair
