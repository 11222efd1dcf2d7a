#include "PlyFile.h"
#include "PlyHeader.h"

#include <vdbhair/io/MeshFile.h>
#include <vdbhair/io/PointFile.h>

#include <vdbhair/Memory.h>
#include <vdbhair/Version.h>
#include <vdbhair/io/ByteReader.h>
#include <vdbhair/io/EdgeChains.h>
#include <vdbhair/io/FileUtil.h>
#include <vdbhair/io/MappedFile.h>
#include <vdbhair/io/TextScanner.h>
#include <vdbhair/Format.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>

namespace vdbhair {

namespace {

using namespace ply;

/// The value of type @a t at @a p (any alignment, little-endian as the host).
double loadValue(PlyType t, const char* p)
{
    auto get = [p](auto v) { std::memcpy(&v, p, sizeof v); return double(v); };
    switch (t) {
    case PlyType::Int8: return get(std::int8_t());
    case PlyType::UInt8: return get(std::uint8_t());
    case PlyType::Int16: return get(std::int16_t());
    case PlyType::UInt16: return get(std::uint16_t());
    case PlyType::Int32: return get(std::int32_t());
    case PlyType::UInt32: return get(std::uint32_t());
    case PlyType::Float32: return get(float());
    case PlyType::Float64: return get(double());
    default: return 0.0;
    }
}

/// Reads values in either encoding; binary reads are bounds-checked by ByteReader.
class ValueSource
{
public:
    ValueSource(ByteReader* bin, TextScanner* text) : mBin(bin), mText(text) {}

    double read(PlyType t, const char* what)
    {
        if (mBin) {
            switch (t) {
            case PlyType::Int8: return mBin->read<std::int8_t>(what);
            case PlyType::UInt8: return mBin->read<std::uint8_t>(what);
            case PlyType::Int16: return mBin->read<std::int16_t>(what);
            case PlyType::UInt16: return mBin->read<std::uint16_t>(what);
            case PlyType::Int32: return mBin->read<std::int32_t>(what);
            case PlyType::UInt32: return mBin->read<std::uint32_t>(what);
            case PlyType::Float32: return mBin->read<float>(what);
            case PlyType::Float64: return mBin->read<double>(what);
            default: mBin->fail("invalid property type");
            }
        }
        while (mTok >= mTokens.size()) {
            if (!mText->nextLine(mTokens)) mText->fail(std::string("file ends before ") + what);
            mTok = 0;
        }
        return mText->toDouble(mTokens[mTok++], what);
    }

    std::string location() const
    {
        return mBin ? "at byte " + std::to_string(mBin->offset()) : "line " + std::to_string(mText->line());
    }
    std::uint64_t remainingBytes() const { return mBin ? mBin->remaining() : mText->remainingBytes(); }
    /// At most how many more values of type @a t there can be: binary values take their size,
    /// ascii ones at least a byte each (the tokens left on the current line, then the rest).
    std::uint64_t valuesLeftAtMost(PlyType t) const
    {
        return mBin ? mBin->remaining() / plySize(t) : mText->remainingBytes() + (mTokens.size() - mTok);
    }
    [[noreturn]] void fail(const std::string& msg) const
    {
        if (mBin) mBin->fail(msg);
        mText->fail(msg);
    }

private:
    ByteReader* mBin;
    TextScanner* mText;
    std::vector<std::string_view> mTokens;
    std::size_t mTok = 0;
};

/// @brief Read the body after @a hdr, element by element and item by item, bounds-checked before
/// anything is allocated. @a onElement(e) runs before an element's items; @a onItem(e, n, values,
/// list, src) after each item, with its scalar property values (by property index) and, for the
/// list property @a listProp of @a listElement, the list's items (other lists are skipped).
/// An element without properties holds no bytes, so its items are not visited at all (its count,
/// up to 2^63-1, is bounded by nothing in the file). @a interrupter (may be null) is polled so
/// that SIGTERM and Ctrl-C end the walk.
template<typename ElementFn, typename ItemFn>
void readPlyBody(const char* data, std::size_t size, const PlyHeader& hdr, const std::string& where, const Element* listElement,
                 int listProp, openvdb::util::NullInterrupter* interrupter, ElementFn&& onElement, ItemFn&& onItem)
{
    InterruptPoll poll(interrupter, where);
    ByteReader bin(data, size, where);
    TextScanner text(data, size, where, hdr.bodyOffset);
    text.setLine(hdr.bodyLine);  // body line numbers continue the header's
    bin.seek(hdr.bodyOffset, "end_header");
    ValueSource src(hdr.binary ? &bin : nullptr, hdr.binary ? nullptr : &text);
    std::vector<double> values, list;
    for (const Element& e : hdr.elements) {
        // Each instance needs at least one byte per property (binary) or two (ascii "0 ").
        std::size_t minBytes = 0;
        for (const Property& p : e.props) minBytes += hdr.binary ? (p.isList ? plySize(p.countType) : plySize(p.type)) : 2;
        if (minBytes && e.count > src.remainingBytes() / minBytes) {
            src.fail("element '" + e.name + "' declares " + std::to_string(e.count) + " items of at least " +
                     std::to_string(minBytes) + " bytes but only " + std::to_string(src.remainingBytes()) + " bytes remain");
        }
        onElement(e);
        if (e.props.empty()) continue;  // nothing to read, whatever the count
        values.assign(e.props.size(), 0.0);
        for (std::uint64_t n = 0; n < e.count; ++n) {
            poll();
            for (std::size_t k = 0; k < e.props.size(); ++k) {
                const Property& p = e.props[k];
                if (!p.isList) {
                    values[k] = src.read(p.type, p.name.c_str());
                    continue;
                }
                const double c = src.read(p.countType, "list count");
                if (!(c >= 0) || c != std::floor(c)) {
                    src.fail("list '" + p.name + "' has count " + formatNumber(c) + "; a list count is a whole number, 0 or more");
                }
                // The count is checked against what is left before it is converted or looped
                // over (only the kept list grows, item by item).
                if (c > double(src.valuesLeftAtMost(p.type))) {
                    src.fail("list '" + p.name + "' declares " + formatNumber(c) + " items but fewer remain in the file");
                }
                const std::uint64_t cnt = std::uint64_t(c);
                const bool keep = &e == listElement && int(k) == listProp;
                if (keep) list.clear();
                for (std::uint64_t j = 0; j < cnt; ++j) {
                    poll();
                    const double v = src.read(p.type, "list item");
                    if (keep) list.push_back(v);
                }
            }
            onItem(e, n, values, list, src);
        }
    }
}


/// Where a PLY's strands come from.
enum class PlyTopology
{
    Strands,  ///< hairutil: an element `strand` with `nsegs`
    Edges,    ///< a line set (Open3D, trimesh): an element `edge` with `vertex1`, `vertex2`
    Runs,     ///< points only (NeuralHaircut, GaussianHaircut): ReadOptions::pointsPerStrand a strand
};

/// @brief The items of a binary element whose properties are all scalars lie @a stride bytes
/// apart: where each property is within an item.
std::vector<std::size_t> propertyOffsets(const Element& e, std::size_t& stride)
{
    std::vector<std::size_t> at;
    stride = 0;
    for (const Property& p : e.props) {
        at.push_back(stride);
        stride += plySize(p.type);
    }
    return at;
}

/// What readPly() reads: the elements, where their properties are (-1: absent) and the topology.
struct PlyStrandLayout
{
    const Element* vertexEl = nullptr;
    const Element* strandEl = nullptr;  ///< null unless the topology is PlyTopology::Strands
    const Element* edgeEl = nullptr;    ///< null unless the topology is PlyTopology::Edges
    PlyTopology topology = PlyTopology::Strands;
    int ix = -1, iy = -1, iz = -1;      ///< the vertex position
    int ir = -1, ig = -1, ib = -1;      ///< the vertex colour
    bool hasColor = false;
    float colorScale = 1.f;             ///< 1/255 for uchar colours
    int iseg = -1;                      ///< the strand's nsegs
    int iv1 = -1, iv2 = -1;             ///< the edge's vertex1 and vertex2
};

/// Step 1: the layout of @a hdr. The topology is hairutil's strand element; else an edge element
/// (a line set); else runs of ReadOptions::pointsPerStrand vertices.
PlyStrandLayout plyStrandLayout(const PlyHeader& hdr, const ReadOptions& opts, ReadReport* report, const std::string& where)
{
    PlyStrandLayout l;
    for (const Element& e : hdr.elements) {
        if (e.name == "vertex") l.vertexEl = &e;
        if (e.name == "strand") l.strandEl = &e;
        if (e.name == "edge") l.edgeEl = &e;
    }
    const Element* vertexEl = l.vertexEl;
    if (!vertexEl) throw FormatError(where + ": the header has no 'vertex' element");
    l.ix = findProperty(vertexEl, "x");
    l.iy = findProperty(vertexEl, "y");
    l.iz = findProperty(vertexEl, "z");
    if (l.ix < 0 || l.iy < 0 || l.iz < 0) throw FormatError(where + ": line " + std::to_string(vertexEl->line) + ": the 'vertex' element needs scalar properties x, y and z");

    l.iv1 = findProperty(l.edgeEl, "vertex1");
    l.iv2 = findProperty(l.edgeEl, "vertex2");
    if (!l.strandEl) {
        if (l.edgeEl && l.iv1 >= 0 && l.iv2 >= 0) {
            l.topology = PlyTopology::Edges;
        } else if (opts.pointsPerStrand > 0) {
            l.topology = PlyTopology::Runs;
        } else if (l.edgeEl) {
            throw FormatError(where + ": line " + std::to_string(l.edgeEl->line) + ": the 'edge' element needs scalar properties vertex1 and vertex2");
        } else {
            throw ParamError<FormatError>({where + ": the file has only points: no 'strand' element (hairutil layout: element strand with property nsegs) "
                                           "and no 'edge' element (a line set); if each run of N consecutive vertices is one strand (NeuralHaircut and "
                                           "GaussianHaircut write 100), read it with ",
                                           readOptionSetting(readParamName("points-per-strand")), "N"});
        }
    } else if (opts.pointsPerStrand > 0 && report) {
        report->warnings.push_back(where + ": " + spelled(readOptionSetting(readParamName("points-per-strand")), opts.spelling) + std::to_string(opts.pointsPerStrand) +
                                   " is ignored: the file's 'strand' element says where each strand ends");
    }
    l.iseg = findProperty(l.strandEl, "nsegs");
    if (l.strandEl && l.iseg < 0) throw FormatError(where + ": line " + std::to_string(l.strandEl->line) + ": the 'strand' element needs an integer property 'nsegs'");
    if (l.topology != PlyTopology::Strands) l.strandEl = nullptr;
    if (l.topology != PlyTopology::Edges) l.edgeEl = nullptr;
    l.ir = findProperty(vertexEl, "red");
    l.ig = findProperty(vertexEl, "green");
    l.ib = findProperty(vertexEl, "blue");
    l.hasColor = l.ir >= 0 && l.ig >= 0 && l.ib >= 0;
    l.colorScale = l.hasColor && vertexEl->props[std::size_t(l.ir)].type == PlyType::UInt8 ? 1.f / 255.f : 1.f;
    if (l.edgeEl && vertexEl->count > std::numeric_limits<std::uint32_t>::max()) {
        throw FormatError(where + ": line " + std::to_string(vertexEl->line) + ": a line set of " + std::to_string(vertexEl->count) +
                          " vertices; edges index at most 2^32-1");
    }
    return l;
}

/// What the body gives: positions and colours straight into the set's arrays, and each strand's
/// vertex count (PlyTopology::Strands) or the edges (PlyTopology::Edges).
struct PlyStrandsIn
{
    explicit PlyStrandsIn(const PlyStrandLayout& l) : layout(l) {}

    /// One edge, checked against the header's vertex count (the 'vertex' element may come after
    /// it); @a fail(msg) throws at the item's place.
    template<typename FailFn>
    void addEdge(std::uint64_t n, double a, double b, FailFn&& fail)
    {
        const std::uint64_t vertexCount = layout.vertexEl->count;
        for (const double v : {a, b}) {
            if (!(v >= 0.0) || v >= double(vertexCount) || v != std::floor(v)) {
                fail("edge " + std::to_string(n) + " names vertex " + formatNumber(v) + " but the 'vertex' element has " +
                     std::to_string(vertexCount) + " (indices are 0-based)");
            }
        }
        const std::uint32_t place = std::uint32_t(std::min<std::uint64_t>(n, 0xffffffffu));
        if (a == b) { ++edges.selfEdges; return; }
        edges.edges.push_back({std::uint32_t(std::min(a, b)), std::uint32_t(std::max(a, b)), place});
    }

    /// One strand's nsegs, checked; @a fail(msg) throws at the item's place.
    template<typename FailFn>
    void addStrand(std::uint64_t n, double s, FailFn&& fail)
    {
        if (s < 0 || s != std::floor(s)) fail("strand " + std::to_string(n) + " has nsegs " + std::to_string(s) + "; it must be a non-negative integer");
        // A float nsegs can be 1e19 or beyond 2^64, and nsegs + 1 summed over strands could
        // wrap 2^64 back to the vertex count: the sum saturates instead (checked by nsegsToStrands()).
        const std::uint64_t c = s < 18446744073709549568.0 ? std::uint64_t(s) + 1 : std::numeric_limits<std::uint64_t>::max();
        nsegsSaturated = nsegsSaturated || c > std::numeric_limits<std::uint64_t>::max() - nsegsSum;
        if (!nsegsSaturated) nsegsSum += c;
        counts.push_back(c);
    }

    const PlyStrandLayout& layout;
    StrandSet out;                      ///< positions and colours (offsets come last)
    std::vector<std::uint64_t> counts;  ///< PlyTopology::Strands: nsegs + 1 a strand
    std::uint64_t nsegsSum = 0;         ///< vertices the strands use
    bool nsegsSaturated = false;        ///< their sum exceeds 2^64-1
    EdgeList edges;                     ///< PlyTopology::Edges
};

/// The @a n vertex items at @a items, @a stride bytes apart (the first at byte @a first, for
/// messages; @a at: where each property is within an item), into positions and colours.
void readVertexItems(const char* items, std::size_t n, std::size_t stride, std::size_t first, const std::vector<std::size_t>& at,
                     const std::string& where, PlyStrandsIn& in)
{
    const PlyStrandLayout& l = in.layout;
    const Element& e = *l.vertexEl;
    std::vector<Vec3f>& positions = in.out.positions;
    reserveHugePages(positions, n);
    positions.resize(n);
    const PlyType tx = e.props[std::size_t(l.ix)].type, ty = e.props[std::size_t(l.iy)].type, tz = e.props[std::size_t(l.iz)].type;
    const std::size_t ox = at[std::size_t(l.ix)], oy = at[std::size_t(l.iy)], oz = at[std::size_t(l.iz)];
    if (tx == PlyType::Float32 && ty == PlyType::Float32 && tz == PlyType::Float32) {
        for (std::size_t k = 0; k < n; ++k) {
            const char* item = items + k * stride;
            float* p = positions[k].asPointer();
            std::memcpy(p, item + ox, 4);
            std::memcpy(p + 1, item + oy, 4);
            std::memcpy(p + 2, item + oz, 4);
        }
    } else {
        for (std::size_t k = 0; k < n; ++k) {
            const char* item = items + k * stride;
            positions[k] = Vec3f(float(loadValue(tx, item + ox)), float(loadValue(ty, item + oy)), float(loadValue(tz, item + oz)));
        }
    }
    if (!allFinite(positions.data(), 3 * n)) {
        for (std::size_t k = 0; k < n; ++k) checkFinite(positions[k], k, where, "at byte " + std::to_string(first + (k + 1) * stride));
    }
    if (l.hasColor) {
        std::vector<Vec3f>& colors = in.out.color;
        reserveHugePages(colors, n);
        colors.resize(n);
        const PlyType tc = e.props[std::size_t(l.ir)].type;
        const std::size_t o[3] = {at[std::size_t(l.ir)], at[std::size_t(l.ig)], at[std::size_t(l.ib)]};
        for (std::size_t k = 0; k < n; ++k) {
            const char* item = items + k * stride;
            for (int c = 0; c < 3; ++c) colors[k][c] = float(loadValue(tc, item + o[c])) * l.colorScale;
        }
    }
}

/// Step 2, for binary without lists (what hairutil, hapPLY and vdbhair write): items of a fixed
/// size, read in place from the file's bytes, with the checks and messages of readPlyBody().
void readFixedSizeBody(const MappedFile& file, const PlyHeader& hdr, const ReadOptions& opts, const std::string& where,
                       PlyStrandsIn& in)
{
    const PlyStrandLayout& l = in.layout;
    ByteReader bin(file.data(), file.size(), where);
    bin.seek(hdr.bodyOffset, "end_header");
    InterruptPoll poll(opts.interrupter, where);
    for (const Element& e : hdr.elements) {
        std::size_t stride = 0;
        const std::vector<std::size_t> at = propertyOffsets(e, stride);
        if (stride && e.count > bin.remaining() / stride) {
            bin.fail("element '" + e.name + "' declares " + std::to_string(e.count) + " items of at least " +
                     std::to_string(stride) + " bytes but only " + std::to_string(bin.remaining()) + " bytes remain");
        }
        if (!stride) continue;  // nothing to read, whatever the count
        const std::size_t first = bin.offset();
        const char* items = bin.current();
        bin.skip(e.count * stride, "items");
        // A failure at item n is placed at the item's end, as readPlyBody() places it.
        auto failAtItem = [&](std::uint64_t n) {
            return [&bin, first, stride, n](const std::string& msg) { bin.failAt(first + (n + 1) * stride, msg); };
        };
        if (&e == l.vertexEl) {
            readVertexItems(items, std::size_t(e.count), stride, first, at, where, in);
        } else if (&e == l.strandEl) {
            in.counts.reserve(e.count);
            const PlyType ts = e.props[std::size_t(l.iseg)].type;
            for (std::uint64_t n = 0; n < e.count; ++n) {
                poll();
                in.addStrand(n, loadValue(ts, items + n * stride + at[std::size_t(l.iseg)]), failAtItem(n));
            }
        } else if (&e == l.edgeEl) {
            in.edges.edges.reserve(e.count);
            const PlyType t1 = e.props[std::size_t(l.iv1)].type, t2 = e.props[std::size_t(l.iv2)].type;
            for (std::uint64_t n = 0; n < e.count; ++n) {
                poll();
                const char* item = items + n * stride;
                in.addEdge(n, loadValue(t1, item + at[std::size_t(l.iv1)]), loadValue(t2, item + at[std::size_t(l.iv2)]), failAtItem(n));
            }
        }
    }
}

/// Step 2, for ascii, or binary with lists: item by item through readPlyBody().
void readAnyBody(const MappedFile& file, const PlyHeader& hdr, const ReadOptions& opts, const std::string& where, PlyStrandsIn& in)
{
    const PlyStrandLayout& l = in.layout;
    std::vector<Vec3f>& positions = in.out.positions;
    std::vector<Vec3f>& colors = in.out.color;
    readPlyBody(file.data(), file.size(), hdr, where, nullptr, -1, opts.interrupter, [&](const Element& e) {
        if (&e == l.vertexEl) { reserveHugePages(positions, e.count); if (l.hasColor) colors.reserve(e.count); }
        if (&e == l.strandEl) in.counts.reserve(e.count);
        if (&e == l.edgeEl) in.edges.edges.reserve(e.count);
    }, [&](const Element& e, std::uint64_t n, const std::vector<double>& values, const std::vector<double>&, ValueSource& src) {
        auto value = [&](int k) { return values[std::size_t(k)]; };
        if (&e == l.vertexEl) {
            const Vec3f pos{float(value(l.ix)), float(value(l.iy)), float(value(l.iz))};
            if (!allFinite(&pos, 3)) checkFinite(pos, positions.size(), where, src.location());
            positions.push_back(pos);
            if (l.hasColor) colors.emplace_back(float(value(l.ir)) * l.colorScale, float(value(l.ig)) * l.colorScale, float(value(l.ib)) * l.colorScale);
        } else if (&e == l.strandEl) {
            in.addStrand(n, value(l.iseg), [&](const std::string& msg) { src.fail(msg); });
        } else if (&e == l.edgeEl) {
            in.addEdge(n, value(l.iv1), value(l.iv2), [&](const std::string& msg) { src.fail(msg); });
        }
    });
}

/// Step 3, a line set: the edges chained into strands as the OBJ reader chains `l` elements.
StrandSet edgesToStrands(PlyStrandsIn& in, const ReadOptions& opts, ReadReport* report, const std::string& where)
{
    if (in.edges.edges.empty()) throw FormatError(where + ": line " + std::to_string(in.layout.vertexEl->line) + ": the 'edge' element joins no two vertices; a line set needs edges");
    const std::vector<Vec3f> vertices = std::move(in.out.positions);
    const std::vector<Vec3f> vertexColors = std::move(in.out.color);
    EdgeNaming naming;  // 0-based vertices, edges by their item number
    StrandSet out = strandsFromEdges(vertices, vertexColors, in.edges, naming, where, opts, report);
    if (report && out.numVertices() < vertices.size()) {
        report->warnings.push_back(where + ": " + std::to_string(vertices.size() - out.numVertices()) + " of " +
                                   std::to_string(vertices.size()) + " vertices are on no edge and were ignored");
    }
    return out;
}

/// Step 3, points in runs: each run of pointsPerStrand consecutive vertices is one strand.
StrandSet runsToStrands(PlyStrandsIn& in, const ReadOptions& opts, ReadReport* report, const std::string& where)
{
    StrandSet& out = in.out;
    const std::size_t line = in.layout.vertexEl->line;
    const std::size_t run = opts.pointsPerStrand, nV = out.positions.size();
    if (nV % run != 0) {
        throw ParamError<FormatError>({where + ": line " + std::to_string(line) + ": the 'vertex' element has " + std::to_string(nV) +
                                           " vertices, which is not a multiple of ",
                                       readOptionSetting(readParamName("points-per-strand")),
                                       std::to_string(run) + " (each run of that many consecutive vertices is one strand)"});
    }
    if (nV > std::numeric_limits<std::uint32_t>::max()) {
        throw FormatError(where + ": line " + std::to_string(line) + ": " + std::to_string(nV) + " vertices; a strand set holds at most 2^32-1");
    }
    ShortStrandFilter filter(opts, report, where);
    if (run < 2) {
        for (std::size_t i = 0; i < nV; ++i) filter.keep(i, run, "vertex " + std::to_string(i));
        out.positions.clear();
        out.color.clear();
    } else {
        out.offsets.reserve(nV / run + 1);
        for (std::size_t v = run; v <= nV; v += run) out.offsets.push_back(std::uint32_t(v));
    }
    filter.finish();
    return std::move(out);
}

/// Step 3, hairutil's strands: the nsegs + 1 must add up to the vertices; the kept strands'
/// vertices move down over the dropped ones' (in place: no copy when nothing is dropped).
StrandSet nsegsToStrands(PlyStrandsIn& in, const ReadOptions& opts, ReadReport* report, const std::string& where)
{
    StrandSet& out = in.out;
    std::vector<Vec3f>& positions = out.positions;
    std::vector<Vec3f>& colors = out.color;
    const bool hasColor = in.layout.hasColor;
    if (in.nsegsSaturated || in.nsegsSum != positions.size()) {
        throw FormatError(where + ": line " + std::to_string(in.layout.strandEl->line) + ": the strands' nsegs + 1 add up to " +
                          (in.nsegsSaturated ? std::string("more than 2^64-1") : std::to_string(in.nsegsSum)) +
                          " vertices but the 'vertex' element has " + std::to_string(positions.size()));
    }
    out.offsets.reserve(in.counts.size() + 1);
    ShortStrandFilter filter(opts, report, where);
    std::size_t v = 0, kept = 0;
    for (std::size_t i = 0; i < in.counts.size(); ++i) {
        const std::size_t n = std::size_t(in.counts[i]);
        if (n >= 2 || filter.keep(i, n, "vertex " + std::to_string(v))) {
            if (kept != v) {
                std::copy(positions.begin() + std::ptrdiff_t(v), positions.begin() + std::ptrdiff_t(v + n), positions.begin() + std::ptrdiff_t(kept));
                if (hasColor) std::copy(colors.begin() + std::ptrdiff_t(v), colors.begin() + std::ptrdiff_t(v + n), colors.begin() + std::ptrdiff_t(kept));
            }
            kept += n;
            out.offsets.push_back(std::uint32_t(kept));
        }
        v += n;
    }
    positions.resize(kept);
    if (hasColor) colors.resize(kept);
    filter.finish();
    return std::move(out);
}

} // namespace

StrandSet readPly(const std::string& path, const ReadOptions& opts, ReadReport* report)
{
    const std::string where = "readPly(" + path + ")";
    const MappedFile file(path, where, opts.interrupter);
    const PlyHeader hdr = parsePlyHeader(file.data(), file.size(), where);
    const PlyStrandLayout layout = plyStrandLayout(hdr, opts, report, where);

    PlyStrandsIn in(layout);
    const bool anyList = std::any_of(hdr.elements.begin(), hdr.elements.end(), [](const Element& e) {
        return std::any_of(e.props.begin(), e.props.end(), [](const Property& p) { return p.isList; });
    });
    if (hdr.binary && !anyList) readFixedSizeBody(file, hdr, opts, where, in);
    else readAnyBody(file, hdr, opts, where, in);

    switch (layout.topology) {
    case PlyTopology::Edges: return edgesToStrands(in, opts, report, where);
    case PlyTopology::Runs: return runsToStrands(in, opts, report, where);
    default: return nsegsToStrands(in, opts, report, where);
    }
}

void writePly(const std::string& path, const StrandSet& strands, PlyEncoding encoding)
{
    const std::string where = "writePly(" + path + ")";
    const std::size_t nS = strands.numStrands(), nV = strands.numVertices();
    if (nV > std::size_t(std::numeric_limits<std::int32_t>::max())) {
        throw ValueError(where + ": " + std::to_string(nV) + " vertices exceed the int32 edge indices of the layout");
    }
    std::size_t maxSegs = 0;
    for (std::size_t i = 0; i < nS; ++i) maxSegs = std::max(maxSegs, strands.size(i) - 1);
    const bool wideSegs = maxSegs > 65535;
    const bool hasColor = !strands.color.empty();
    const bool binary = encoding == PlyEncoding::Binary;

    std::string out;
    reserveHugePages(out, 256 + (binary ? 15 : 40) * nV + 16 * nV);
    out += "ply\nformat ";
    out += binary ? "binary_little_endian 1.0\n" : "ascii 1.0\n";
    out += std::string("comment ") + creatorString() + "\n";
    out += "element vertex " + std::to_string(nV) + "\nproperty float x\nproperty float y\nproperty float z\n";
    if (hasColor) out += "property uchar red\nproperty uchar green\nproperty uchar blue\n";
    out += "element strand " + std::to_string(nS) + "\nproperty " + (wideSegs ? "uint" : "ushort") + " nsegs\n";
    out += "element edge " + std::to_string(nV - nS) + "\nproperty int vertex1\nproperty int vertex2\nend_header\n";

    char buf[32];
    auto putText = [&](auto v, char sep) {
        const auto res = std::to_chars(buf, buf + sizeof buf, v);
        out.append(buf, res.ptr);
        out.push_back(sep);
    };
    auto putBin = [&](const auto& v) { out.append(reinterpret_cast<const char*>(&v), sizeof v); };
    auto toByte = [](float c) { return std::uint8_t(std::lround(std::min(1.f, std::max(0.f, c)) * 255.f)); };

    for (std::size_t v = 0; v < nV; ++v) {
        const Vec3f& p = strands.positions[v];
        if (binary) {
            putBin(p.x()); putBin(p.y()); putBin(p.z());
            if (hasColor) for (int c = 0; c < 3; ++c) putBin(toByte(strands.color[v][c]));
        } else {
            putText(p.x(), ' '); putText(p.y(), ' '); putText(p.z(), hasColor ? ' ' : '\n');
            if (hasColor) for (int c = 0; c < 3; ++c) putText(unsigned(toByte(strands.color[v][c])), c == 2 ? '\n' : ' ');
        }
    }
    for (std::size_t i = 0; i < nS; ++i) {
        const std::size_t segs = strands.size(i) - 1;
        if (binary) {
            if (wideSegs) putBin(std::uint32_t(segs));
            else putBin(std::uint16_t(segs));
        } else {
            putText(segs, '\n');
        }
    }
    for (std::size_t i = 0; i < nS; ++i) {
        for (std::size_t v = strands.begin(i); v + 1 < strands.end(i); ++v) {
            if (binary) { putBin(std::int32_t(v)); putBin(std::int32_t(v + 1)); }
            else { putText(v, ' '); putText(v + 1, '\n'); }
        }
    }
    writeFileAtomic(path, out, where);
}

TriangleMesh readPlyMesh(const std::string& path)
{
    const std::string where = "readPlyMesh(" + path + ")";
    const MappedFile file(path, where);
    const PlyHeader hdr = parsePlyHeader(file.data(), file.size(), where);
    const Element* vertexEl = nullptr;
    const Element* faceEl = nullptr;
    for (const Element& e : hdr.elements) {
        if (e.name == "vertex") vertexEl = &e;
        if (e.name == "face") faceEl = &e;
    }
    if (!vertexEl) throw FormatError(where + ": the header has no 'vertex' element");
    if (!faceEl) throw FormatError(where + ": the header has no 'face' element");
    const int ix = findProperty(vertexEl, "x"), iy = findProperty(vertexEl, "y"), iz = findProperty(vertexEl, "z");
    const int iface = std::max(findProperty(faceEl, "vertex_indices", true), findProperty(faceEl, "vertex_index", true));
    if (ix < 0 || iy < 0 || iz < 0) throw FormatError(where + ": line " + std::to_string(vertexEl->line) + ": the 'vertex' element needs scalar properties x, y and z");
    if (iface < 0) throw FormatError(where + ": line " + std::to_string(faceEl->line) + ": the 'face' element needs a list 'vertex_indices'");

    TriangleMesh mesh;
    readPlyBody(file.data(), file.size(), hdr, where, faceEl, iface, nullptr, [&](const Element& e) {
        if (&e == vertexEl) mesh.vertices.reserve(e.count);
        if (&e == faceEl) mesh.triangles.reserve(e.count);
    }, [&](const Element& e, std::uint64_t n, const std::vector<double>& values, const std::vector<double>& face, ValueSource& src) {
        if (&e == vertexEl) {
            const Vec3f pos{float(values[std::size_t(ix)]), float(values[std::size_t(iy)]), float(values[std::size_t(iz)])};
            checkFinite(pos, mesh.vertices.size(), where, src.location());
            mesh.vertices.push_back(pos);
        } else if (&e == faceEl) {
            for (double idx : face) {
                if (!(idx >= 0.0) || idx >= double(mesh.vertices.size()) || idx != std::floor(idx)) {
                    src.fail("face " + std::to_string(n) + " names vertex " + std::to_string(idx) + " of " + std::to_string(mesh.vertices.size()));
                }
            }
            if (face.size() < 3) src.fail("face " + std::to_string(n) + " has " + std::to_string(face.size()) + " vertices; a face needs 3");
            for (std::size_t j = 1; j + 1 < face.size(); ++j) {
                mesh.triangles.push_back({std::uint32_t(face[0]), std::uint32_t(face[j]), std::uint32_t(face[j + 1])});
            }
        }
    });
    if (mesh.triangles.empty()) throw FormatError(where + ": the file has no faces");
    return mesh;
}

} // namespace vdbhair

// Oriented points (PointFile.h): the vertex element only; here for the shared PLY parser.
namespace vdbhair {

OrientedPoints readPlyPoints(const std::string& path)
{
    const std::string where = "readPlyPoints(" + path + ")";
    const MappedFile file(path, where);
    const PlyHeader hdr = parsePlyHeader(file.data(), file.size(), where);
    const Element* vertexEl = &vertexElement(hdr, where);
    const int ix = findProperty(vertexEl, "x"), iy = findProperty(vertexEl, "y"), iz = findProperty(vertexEl, "z");
    if (ix < 0 || iy < 0 || iz < 0) throw FormatError(where + ": line " + std::to_string(vertexEl->line) + ": the 'vertex' element needs scalar properties x, y and z");
    const int inx = findProperty(vertexEl, "nx"), iny = findProperty(vertexEl, "ny"), inz = findProperty(vertexEl, "nz");
    const int itx = findProperty(vertexEl, "tx"), ity = findProperty(vertexEl, "ty"), itz = findProperty(vertexEl, "tz");
    const bool hasN = inx >= 0 && iny >= 0 && inz >= 0, hasT = itx >= 0 && ity >= 0 && itz >= 0;

    OrientedPoints pts;
    readPlyBody(file.data(), file.size(), hdr, where, nullptr, -1, nullptr, [&](const Element& e) {
        if (&e == vertexEl) pts.positions.reserve(e.count);
    }, [&](const Element& e, std::uint64_t, const std::vector<double>& v, const std::vector<double>&, ValueSource& src) {
        if (&e != vertexEl) return;
        auto vec = [&](int a, int b, int c) { return Vec3f(float(v[std::size_t(a)]), float(v[std::size_t(b)]), float(v[std::size_t(c)])); };
        const Vec3f p = vec(ix, iy, iz);
        checkFinite(p, pts.positions.size(), where, src.location());
        pts.positions.push_back(p);
        if (hasN) {
            const Vec3f n = vec(inx, iny, inz);
            checkFinite(n, pts.normals.size(), where, src.location());
            pts.normals.push_back(n);
        }
        if (hasT) pts.tangents.push_back(vec(itx, ity, itz));
    });
    return pts;
}

std::vector<float> readPlyVertexValues(const std::string& path, const std::string& property)
{
    const std::string where = "readPlyVertexValues(" + path + ")";
    const MappedFile file(path, where);
    const PlyHeader hdr = parsePlyHeader(file.data(), file.size(), where);
    const Element* vertexEl = &vertexElement(hdr, where);
    const int ip = findProperty(vertexEl, property.c_str());
    if (ip < 0) {
        std::string names;
        for (const Property& p : vertexEl->props) names += (names.empty() ? "" : ", ") + p.name;
        throw FormatError(where + ": the 'vertex' element has no scalar property '" + property + "' (it has " + names + ")");
    }
    const bool colour = property == "red" || property == "green" || property == "blue" || property == "alpha";
    const double scale = colour && vertexEl->props[std::size_t(ip)].type == PlyType::UInt8 ? 1.0 / 255.0 : 1.0;
    std::vector<float> values;
    readPlyBody(file.data(), file.size(), hdr, where, nullptr, -1, nullptr, [&](const Element& e) {
        if (&e == vertexEl) values.reserve(e.count);
    }, [&](const Element& e, std::uint64_t, const std::vector<double>& v, const std::vector<double>&, ValueSource& src) {
        if (&e != vertexEl) return;
        const double x = v[std::size_t(ip)] * scale;
        if (!std::isfinite(x) || std::abs(x) > double(std::numeric_limits<float>::max())) {
            throw FormatError(where + ": " + src.location() + ": vertex " + std::to_string(values.size()) + " has " + property + " " +
                              std::to_string(x) + "; values must be finite floats");
        }
        values.push_back(float(x));
    });
    return values;
}

std::uint64_t plyElementCount(const std::string& path, const std::string& element)
{
    const std::string where = "readPly(" + path + ")";
    const MappedFile file(path, where);
    const PlyHeader hdr = parsePlyHeader(file.data(), file.size(), where);
    for (const Element& e : hdr.elements) {
        if (e.name == element) return e.count;
    }
    return 0;
}

} // namespace vdbhair
