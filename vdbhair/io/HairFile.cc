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

/// What the 128-byte cyHair header declares (HairFile.h has the layout).
struct HairHeader
{
    std::uint64_t strands = 0, points = 0;  ///< the strand and point counts
    std::uint32_t arrays = 0;               ///< which arrays follow: the k* bits
    std::uint32_t defSegments = 0;          ///< every strand's segments when there is no segments array
    StrandDefaults defaults;
};

/// Step 1: the header, with its array bits checked; @a in is left at byte 128.
HairHeader readHairHeader(ByteReader& in, const MappedFile& file)
{
    if (file.size() < 4 || std::memcmp(file.data(), "HAIR", 4) != 0) {
        in.fail("not a cyHair file: the first 4 bytes must be \"HAIR\"");
    }
    if (file.size() < 128) {
        in.fail("the file has " + std::to_string(file.size()) +
                " bytes, shorter than the 128-byte cyHair header");
    }
    HairHeader h;
    in.skip(4, "magic");
    h.strands = in.read<std::uint32_t>("strand count");
    h.points = in.read<std::uint32_t>("point count");
    h.arrays = in.read<std::uint32_t>("array bits");
    h.defSegments = in.read<std::uint32_t>("default segments");
    h.defaults.thickness = in.read<float>("default thickness");
    h.defaults.transparency = in.read<float>("default transparency");
    in.readArray(&h.defaults.color[0], 3, "default colour");
    in.seek(128, "header end");

    if (h.arrays & ~std::uint32_t(31)) {
        in.failAt(12, "array bits " + std::to_string(h.arrays) +
                          " set unknown bits; only 1, 2, 4, 8 and 16 are defined");
    }
    if (!(h.arrays & kPoints)) in.failAt(12, "the array bits have no points array (bit 2); there are no positions to read");
    return h;
}

/// Step 2: the counts are possible before anything is sized by them. The file size must be
/// exactly what the header describes (more is a warning), and every strand has at least one
/// point (segments + 1), so the point count bounds the strand count (2^32-1 strands of 0
/// points would need no bytes).
void checkHairCounts(const ByteReader& in, const HairHeader& h, std::size_t fileSize, const std::string& where,
                     ReadReport* report)
{
    const std::uint64_t nS = h.strands, nP = h.points;
    std::uint64_t expected = 128;
    if (h.arrays & kSegments) expected += 2 * nS;
    expected += 12 * nP;
    if (h.arrays & kThickness) expected += 4 * nP;
    if (h.arrays & kTransparency) expected += 4 * nP;
    if (h.arrays & kColors) expected += 12 * nP;
    if (expected > fileSize) {
        in.failAt(4, "the header declares " + std::to_string(nS) + " strands and " +
                         std::to_string(nP) + " points, which need " + std::to_string(expected) +
                         " bytes, but the file has only " + std::to_string(fileSize));
    }
    if (expected < fileSize && report) {
        report->warnings.push_back(where + ": " + std::to_string(fileSize - expected) +
                                   " bytes after the arrays the header describes were ignored");
    }
    if (nS > nP) {
        in.failAt(4, "the header declares " + std::to_string(nS) + " strands but only " + std::to_string(nP) +
                         " points; every strand has at least one point");
    }
    if (!(h.arrays & kSegments) && h.defSegments < 65536u && nS * (std::uint64_t(h.defSegments) + 1) != nP) {
        in.failAt(8, "the strands' point counts add up to " + std::to_string(nS * (std::uint64_t(h.defSegments) + 1)) +
                         " but the header declares " + std::to_string(nP) + " points (no segments array: every strand has default segments " +
                         std::to_string(h.defSegments) + " + 1 points)");
    }
}

/// Step 3: the points of each strand, from the segments array (@a in moves past it) or the
/// default, checked to add up to the header's point count.
std::vector<std::uint32_t> strandPointCounts(ByteReader& in, const HairHeader& h)
{
    const std::uint64_t nS = h.strands, nP = h.points;
    std::vector<std::uint32_t> counts(nS);
    if (h.arrays & kSegments) {
        std::vector<std::uint16_t> seg(nS);
        in.readArray(seg.data(), nS, "segments array");
        for (std::size_t i = 0; i < nS; ++i) counts[i] = std::uint32_t(seg[i]) + 1;
    } else {
        if (h.defSegments >= 65536u) {
            in.failAt(16, "default segments " + std::to_string(h.defSegments) +
                              " exceeds the format's limit of 65535");
        }
        std::fill(counts.begin(), counts.end(), h.defSegments + 1);
    }
    std::uint64_t sum = 0;
    for (std::uint32_t c : counts) sum += c;
    if (sum != nP) {
        in.failAt(8, "the strands' point counts add up to " + std::to_string(sum) +
                         " but the header declares " + std::to_string(nP) + " points" +
                         ((h.arrays & kSegments) ? "" : " (no segments array: every strand has default segments " +
                                                            std::to_string(h.defSegments) + " + 1 points)"));
    }
    return counts;
}

/// Where the per-point arrays lie in the file's bytes (null: the array is absent).
struct HairArrays
{
    std::size_t pointsAt = 0;  ///< the points array's byte offset, for messages
    const char* points = nullptr;
    const char* thickness = nullptr;
    const char* transparency = nullptr;
    const char* colors = nullptr;
};

/// Step 4: where each array lies, from @a in's place after the segments (the size check of
/// checkHairCounts() covers them all).
HairArrays locateArrays(const ByteReader& in, const HairHeader& h, const char* data)
{
    const std::uint64_t nP = h.points;
    HairArrays a;
    a.pointsAt = in.offset();
    in.require(nP, 12, "points array");
    std::size_t at = a.pointsAt + 12 * nP;
    auto arrayAt = [&](std::uint32_t bit, std::size_t bytesPerPoint) -> const char* {
        if (!(h.arrays & bit)) return nullptr;
        const char* p = data + at;
        at += bytesPerPoint * nP;
        return p;
    };
    a.points = data + a.pointsAt;
    a.thickness = arrayAt(kThickness, 4);
    a.transparency = arrayAt(kTransparency, 4);
    a.colors = arrayAt(kColors, 12);
    return a;
}

/// Append points [@a v, @a v + @a n) of the array at @a src (@a bytesPerPoint each) to @a dst;
/// nothing for an absent array.
template<typename T>
void appendPoints(std::vector<T>& dst, const char* src, std::size_t bytesPerPoint, std::size_t v, std::size_t n)
{
    if (!src || n == 0) return;  // (memcpy to an empty vector's null data is undefined, even of 0 bytes)
    const std::size_t old = dst.size();
    dst.resize(old + n);
    std::memcpy(reinterpret_cast<char*>(dst.data() + old), src + bytesPerPoint * v, bytesPerPoint * n);
}

/// Step 5, the common case: each array copied once, whole, from the file's bytes to @a out, the
/// positions checked piece by piece (pieces that stay in the cache while they are copied and
/// checked). Returns false, with @a out's positions part-filled, when a coordinate is not finite.
bool copyWholeArrays(StrandSet& out, const HairArrays& a, const std::vector<std::uint32_t>& counts, std::size_t nP)
{
    constexpr std::size_t kPiece = std::size_t(1) << 14;
    for (std::size_t v = 0; v < nP; v += kPiece) {
        const std::size_t n = std::min<std::size_t>(kPiece, nP - v);
        appendPoints(out.positions, a.points, 12, v, n);
        if (!allFinite(out.positions.data() + v, 3 * n)) return false;
    }
    appendPoints(out.thickness, a.thickness, 4, 0, nP);
    appendPoints(out.transparency, a.transparency, 4, 0, nP);
    appendPoints(out.color, a.colors, 12, 0, nP);
    const std::size_t nS = counts.size();
    out.offsets.resize(nS + 1);
    for (std::size_t i = 0; i < nS; ++i) out.offsets[i + 1] = out.offsets[i] + counts[i];
    return true;
}

/// Step 5, otherwise: strand by strand, to name the first non-finite point and to drop the
/// strands @a filter drops.
void copyStrandByStrand(StrandSet& out, const HairArrays& a, const std::vector<std::uint32_t>& counts, std::size_t nP,
                        ShortStrandFilter& filter, const ReadOptions& opts, const std::string& where)
{
    out.positions.clear();
    const bool finite = allFinite(a.points, 3 * nP);
    InterruptPoll poll(opts.interrupter, where);
    std::size_t v = 0;
    for (std::size_t i = 0; i < counts.size(); ++i) {
        poll();
        const std::size_t n = counts[i];
        for (std::size_t k = v; !finite && k < v + n; ++k) {
            Vec3f p;
            std::memcpy(p.asPointer(), a.points + 12 * k, 12);
            checkFinite(p, k, where, "at byte " + std::to_string(a.pointsAt + 12 * k));
        }
        if (filter.keep(i, n, "strand at point " + std::to_string(v))) {
            appendPoints(out.positions, a.points, 12, v, n);
            out.offsets.push_back(std::uint32_t(out.positions.size()));
            appendPoints(out.thickness, a.thickness, 4, v, n);
            appendPoints(out.transparency, a.transparency, 4, v, n);
            appendPoints(out.color, a.colors, 12, v, n);
        }
        v += n;
    }
}

} // namespace

StrandSet readHair(const std::string& path, const ReadOptions& opts, ReadReport* report)
{
    const std::string where = "readHair(" + path + ")";
    const MappedFile file(path, where, opts.interrupter);
    ByteReader in(file.data(), file.size(), where);

    const HairHeader header = readHairHeader(in, file);
    checkHairCounts(in, header, file.size(), where, report);
    const std::vector<std::uint32_t> counts = strandPointCounts(in, header);
    const HairArrays arrays = locateArrays(in, header, file.data());

    // Strands: each array is copied once, from the file's bytes to the set; only a file that
    // fails the finiteness check or has strands to drop is walked strand by strand (to name the
    // culprit, to filter).
    const std::size_t nP = std::size_t(header.points);
    StrandSet out;
    out.defaults = header.defaults;
    out.reserve(std::size_t(header.strands), nP);
    ShortStrandFilter filter(opts, report, where);
    const bool anyShort = std::any_of(counts.begin(), counts.end(), [](std::uint32_t c) { return c < 2; });
    if (anyShort || !copyWholeArrays(out, arrays, counts, nP)) {
        copyStrandByStrand(out, arrays, counts, nP, filter, opts, where);
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
