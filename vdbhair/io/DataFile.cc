#include "DataFile.h"

#include <vdbhair/Memory.h>

#include <vdbhair/io/ByteReader.h>
#include <vdbhair/io/FileUtil.h>
#include <vdbhair/io/MappedFile.h>

#include <vdbhair/strands/Summary.h>

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <cmath>
#include <cstring>
#include <exception>
#include <limits>
#include <vector>

namespace vdbhair {

namespace {

/// One strand of a .data file where it lies in the file (scanData()).
struct DataSpan
{
    std::size_t countAt;     ///< byte of its vertex count
    std::size_t posAt;       ///< byte of its first position
    std::size_t first;       ///< index of its first vertex among the kept strands' vertices
    std::uint32_t vertices;
    bool kept;               ///< false: dropped for having fewer than 2 vertices
};

/// The strands of a .data file (@a bytes, read through @a in) in file order, up to the first fault:
/// a count that is negative or larger than what remains, a short strand refused, more than 2^32-1
/// vertices, or whatever @a visit throws. @a visit(span) sees each strand as soon as its count is
/// read, before it is kept or dropped (readData() copies and checks its values there, in one pass
/// over the file). The fault is kept in @a fault, not thrown: a reader that checks values later
/// (summarizeData()) checks the strands before it first and throws whichever comes first in the
/// file, as one pass in file order would.
template<typename Visit>
std::vector<DataSpan> scanData(const char* bytes, ByteReader& in, const ReadOptions& opts, ReadReport* report,
                               const std::string& where, std::exception_ptr& fault, const Visit& visit)
{
    std::vector<DataSpan> spans;
    try {
        const std::int32_t nS = in.read<std::int32_t>("strand count");
        if (nS < 0) in.failAt(0, "strand count " + std::to_string(nS) + " is negative");
        // Every strand needs at least its 4-byte vertex count.
        in.require(std::uint64_t(nS), 4, "the declared " + std::to_string(nS) + " strands");
        spans.reserve(std::size_t(nS));
        ShortStrandFilter filter(opts, report, where);
        InterruptPoll poll(opts.interrupter, where);
        std::size_t total = 0, ahead = in.offset();
        // Messages (and their locations) are built only for a strand that fails: building them for
        // every strand and vertex took three quarters of the time to read a 77 MB file.
        for (std::int32_t i = 0; i < nS; ++i) {
            poll();
            // Each count says where the next begins: a chain of loads, each a cache miss unless the
            // bytes ahead are already on their way. Keep the next 4 KiB requested.
            for (const std::size_t to = std::min(in.size(), in.offset() + 4096); ahead < to; ahead += 64) __builtin_prefetch(bytes + ahead);
            const std::size_t at = in.offset();
            const std::int32_t nV = in.read<std::int32_t>("vertex count");
            if (nV < 0) in.failAt(at, "strand " + std::to_string(i) + " declares " + std::to_string(nV) + " vertices; counts must not be negative");
            if (std::uint64_t(nV) > in.remaining() / 12) {
                in.failAt(at, "strand " + std::to_string(i) + " declares " + std::to_string(nV) +
                                  " vertices (" + std::to_string(12ull * std::uint64_t(nV)) +
                                  " bytes) but only " + std::to_string(in.remaining()) + " bytes remain");
            }
            const std::size_t posAt = in.offset();
            in.seek(posAt + 12 * std::size_t(nV), "vertices");
            spans.push_back({at, posAt, total, std::uint32_t(nV), true});
            visit(spans.back());
            if (nV >= 2 || filter.keep(std::size_t(i), std::size_t(nV), "at byte " + std::to_string(at))) {
                total += std::size_t(nV);
                if (total > std::numeric_limits<std::uint32_t>::max()) in.fail("more than 2^32-1 vertices");
            } else {
                spans.back().kept = false;
            }
        }
        if (in.remaining() && report) {
            report->warnings.push_back(where + ": " + std::to_string(in.remaining()) +
                                       " bytes after the last strand were ignored");
        }
        filter.finish();
    } catch (const InterruptedError&) {
        throw;
    } catch (...) {
        fault = std::current_exception();
    }
    return spans;
}

/// @throw FormatError naming the first non-finite coordinate of @a span (at @a src in the file),
/// when @a finite says it has one.
void throwIfNonFinite(const DataSpan& span, const char* src, bool finite, const std::string& where)
{
    if (finite) return;
    for (std::size_t k = 0; k < span.vertices; ++k) {
        Vec3f v;
        std::memcpy(&v, src + 12 * k, 12);
        checkFinite(v, span.first + k, where, "at byte " + std::to_string(span.posAt + 12 * k));
    }
}

/// The vertices of the kept strands before @a spans' end.
std::size_t keptVertices(const std::vector<DataSpan>& spans)
{
    return spans.empty() ? 0 : spans.back().first + (spans.back().kept ? spans.back().vertices : 0);
}

} // namespace

StrandSet readData(const std::string& path, const ReadOptions& opts, ReadReport* report)
{
    const std::string where = "readData(" + path + ")";
    const MappedFile file(path, where, opts.interrupter);
    ByteReader in(file.data(), file.size(), where);
    StrandSet out;
    std::exception_ptr fault;
    // The counts first (a chain of loads through the file), then every strand's positions copied
    // and checked in parallel, into storage the threads fault in together (prefaultPages()).
    const std::vector<DataSpan> spans = scanData(file.data(), in, opts, report, where, fault, [](const DataSpan&) {});
    const std::size_t total = keptVertices(spans);
    reserveHugePages(out.positions, total);
    prefaultPages(out.positions.data(), total * sizeof(Vec3f), true);
    out.positions.resize(total);
    std::vector<char> finite(spans.size(), 1);
    forEachIndex(spans.size(), true, [&](std::size_t i) {
        const DataSpan& sp = spans[i];
        if (sp.vertices == 0) return;  // nothing to copy (and no storage at all when every strand is empty)
        const char* src = file.data() + sp.posAt;
        if (sp.kept) {
            float* dst = reinterpret_cast<float*>(out.positions.data() + sp.first);
            std::memcpy(dst, src, 12 * std::size_t(sp.vertices));
            finite[i] = allFinite(dst, 3 * std::size_t(sp.vertices)) ? 1 : 0;
        } else {
            // A dropped strand (fewer than 2 vertices) is checked too, as one pass in file order would.
            float v[3];
            for (std::size_t k = 0; k < sp.vertices && finite[i]; ++k) {
                std::memcpy(v, src + 12 * k, 12);
                finite[i] = allFinite(v, 3) ? 1 : 0;
            }
        }
    }, 256);
    // The first fault in file order: a strand's values before a later count's fault.
    for (std::size_t i = 0; i < spans.size(); ++i) throwIfNonFinite(spans[i], file.data() + spans[i].posAt, finite[i] != 0, where);
    if (fault) std::rethrow_exception(fault);
    out.reserve(spans.size(), 0);
    for (const DataSpan& sp : spans) {
        if (sp.kept) out.offsets.push_back(std::uint32_t(sp.first + sp.vertices));
    }
    return out;
}

StrandSummary summarizeData(const std::string& path, const ReadOptions& opts, ReadReport* report)
{
    const std::string where = "readData(" + path + ")";
    const MappedFile file(path, where, opts.interrupter);
    ByteReader in(file.data(), file.size(), where);
    std::exception_ptr fault;
    const std::vector<DataSpan> spans = scanData(file.data(), in, opts, report, where, fault, [](const DataSpan&) {});
    // In parallel: every strand's values checked, the kept ones' lengths and bounds measured,
    // each copied into a buffer of the thread's (the file's bytes are not aligned as Vec3f).
    std::vector<char> finite(spans.size(), 1);
    std::vector<float> lengths(spans.size(), 0.f);
    tbb::enumerable_thread_specific<BBox> boxes;
    tbb::enumerable_thread_specific<std::vector<Vec3f>> buffers;
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, spans.size(), 256), [&](const tbb::blocked_range<std::size_t>& r) {
        std::vector<Vec3f>& buf = buffers.local();
        BBox& box = boxes.local();
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
            const DataSpan& sp = spans[i];
            buf.resize(sp.vertices);
            std::memcpy(buf.data(), file.data() + sp.posAt, 12 * std::size_t(sp.vertices));
            finite[i] = allFinite(buf.data(), 3 * std::size_t(sp.vertices)) ? 1 : 0;
            if (!sp.kept || !finite[i]) continue;
            lengths[i] = float(polylineLength(buf.data(), buf.size()));
            for (const Vec3f& p : buf) box.expand(p);
        }
    });
    // The first fault in file order, as readData() would meet it.
    for (std::size_t i = 0; i < spans.size(); ++i) throwIfNonFinite(spans[i], file.data() + spans[i].posAt, finite[i] != 0, where);
    if (fault) std::rethrow_exception(fault);
    BBox bbox;
    for (const BBox& b : boxes) {
        if (!b.empty()) { bbox.expand(b.min); bbox.expand(b.max); }
    }
    std::vector<float> keptLengths;
    std::vector<std::uint32_t> counts;
    for (std::size_t i = 0; i < spans.size(); ++i) {
        if (!spans[i].kept) continue;
        keptLengths.push_back(lengths[i]);
        counts.push_back(spans[i].vertices);
    }
    return summarizeStrands(keptVertices(spans), bbox, keptLengths, counts);
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
