/// @file Memory.h
/// @brief How much memory there is, how a request for more is refused before it allocates, and
/// large buffers that fill fast: a hint for transparent huge pages.
///
/// A fresh buffer costs one page fault per 4 KiB page the first time it is written. On the
/// virtual machines vdbhair is measured on a fault costs about 20 µs, so the 77 MB of positions
/// of a 100,000-strand × 64-vertex hairstyle took 0.45 s to fault in against 0.03 s to copy. With
/// huge pages (2 MiB, one fault for 512 small pages) the same buffer faults in within 0.03 s.
/// Linux gives them only to memory that asks (`transparent_hugepage` set to `madvise`, Debian's
/// default), so the library asks for its large, freshly written arrays: readers' positions,
/// retraced strands, the bytes writers assemble.
#pragma once

#include <vdbhair/Parallel.h>
#include <vdbhair/Parameters.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <new>
#include <string>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace vdbhair {

/// @brief @a maxMemory if set (> 0), else MemAvailable of /proc/meminfo (the memory the kernel
/// can give without swapping), else (no such file) the largest value: no limit.
std::uint64_t availableMemoryBytes(std::uint64_t maxMemory = 0);

/// @brief Bytes as a person reads them: "1.37 GiB", "512 MiB", "900 B".
std::string formatBytes(std::uint64_t bytes);

/// @brief Refuse up front: LimitError "<where>: needs about <estimate> (<how>), more than the
/// <available> available (MemAvailable)[ of maxMemory]; <advice>" when @a estimate exceeds
/// availableMemoryBytes(@a maxMemory). Call it before allocating what a count from a file or a
/// parameter asks for.
/// @param how what the estimate holds, e.g. "1e9 vertices of 12 bytes"
/// @param advice what to change, e.g. "fewer vertices per strand"
void checkMemory(const std::string& where, std::uint64_t estimate, const std::string& how, const std::string& advice,
                 std::uint64_t maxMemory = 0);
/// @brief As above, the advice and the cap naming parameters: a ParamError<LimitError> that names
/// the cap @a maxMemory as @a maxMemoryName (its declaration's paramName()).
void checkMemory(const std::string& where, std::uint64_t estimate, const std::string& how, const ParamText& advice,
                 std::uint64_t maxMemory, const ParamName& maxMemoryName);

/// @brief What an AllocationBudget throws from operator new: the request that would have taken
/// the calling thread's live bytes past the budget. A std::bad_alloc, so code that copes with an
/// allocation failing copes with this one (nothrow new returns null).
class BudgetExceeded : public std::bad_alloc
{
public:
    BudgetExceeded(std::uint64_t requested, std::uint64_t live, std::uint64_t limit);
    const char* what() const noexcept override { return mWhat; }
    std::uint64_t requested() const { return mRequested; }
    std::uint64_t live() const { return mLive; }
    std::uint64_t limit() const { return mLimit; }

private:
    std::uint64_t mRequested, mLive, mLimit;
    char mWhat[160];  // built without allocating: it is made inside operator new
};

/// @brief While alive, every `operator new` of the calling thread is counted against @a limit
/// bytes: the live bytes (malloc_usable_size of each block, less each block freed) may not pass
/// it, and a request that would throws BudgetExceeded before anything is allocated. Other
/// threads are not counted. The library replaces the global operator new and delete to do this
/// (Memory.cc); with no budget alive they cost one thread-local load.
///
/// Readers of files whose contents another library allocates (OpenVDB's tree reader) open one
/// with readBudgetBytes() of the file's size: a size field the file states beyond what its bytes
/// can hold then fails as a typed error instead of exhausting memory. Budgets nest: an inner one
/// is held to what its outer one has left, and its live bytes count in the outer one when it ends.
class AllocationBudget
{
public:
    explicit AllocationBudget(std::uint64_t limit);
    ~AllocationBudget();
    AllocationBudget(const AllocationBudget&) = delete;
    AllocationBudget& operator=(const AllocationBudget&) = delete;

    std::uint64_t limit() const { return mLimit; }
    std::uint64_t live() const { return mLive; }
    std::uint64_t peak() const { return mPeak; }  ///< the most live bytes at any time

    // For operator new and delete (Memory.cc).
    void charge(std::size_t request);
    void add(std::size_t usable) { mLive += usable; mPeak = std::max(mPeak, mLive); }
    void release(std::size_t usable) { mLive -= std::min<std::uint64_t>(mLive, usable); }
    static AllocationBudget* current();

private:
    std::uint64_t mLimit, mLive = 0, mPeak = 0;
    AllocationBudget* mOuter;
};

/// @brief The budget for reading a file of @a fileBytes whose reader allocates what the file
/// declares: kReadBudgetPerFileByte times its size plus kReadBudgetFloor, and never more than
/// availableMemoryBytes(@a maxMemory). The factor is 2.5 times the densest legitimate expansion of
/// a `.vdb` found (TestVdbBudget.cc): one Vec3d voxel alone in its branch of internal nodes holds
/// 103 bytes per byte of file (tables of 32^3 and 16^3 values written as masks), fully active
/// leaves of equal Vec3d 49, a strands grid 33, a level set 6.
constexpr std::uint64_t kReadBudgetPerFileByte = 256;
constexpr std::uint64_t kReadBudgetFloor = std::uint64_t(64) << 20;
std::uint64_t readBudgetBytes(std::uint64_t fileBytes, std::uint64_t maxMemory = 0);

/// @brief Ask for transparent huge pages over the 2 MiB-aligned part of [p, p + bytes); a hint
/// that changes no contents (nothing happens below 4 MiB, or where the kernel declines).
inline void adviseHugePages(const void* p, std::size_t bytes)
{
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    constexpr std::uintptr_t kHuge = std::uintptr_t(2) << 20;
    if (!p || bytes < 2 * kHuge) return;
    const std::uintptr_t lo = (reinterpret_cast<std::uintptr_t>(p) + kHuge - 1) & ~(kHuge - 1);
    const std::uintptr_t hi = (reinterpret_cast<std::uintptr_t>(p) + bytes) & ~(kHuge - 1);
    if (hi > lo) ::madvise(reinterpret_cast<void*>(lo), hi - lo, MADV_HUGEPAGE);
#else
    (void)p;
    (void)bytes;
#endif
}

/// @brief @a v.reserve(@a n), with its storage hinted for huge pages (adviseHugePages()), for a
/// std::vector or the std::string a writer builds its file in.
template<typename ContainerT>
void reserveHugePages(ContainerT& v, std::size_t n)
{
    v.reserve(n);
    adviseHugePages(v.data(), v.capacity() * sizeof(*v.data()));
}

/// @brief Write a zero byte into every 4 KiB page of the storage [p, p + bytes), from TBB's
/// threads when @a threaded: the first touch of fresh memory is the kernel's work (a fault, and
/// zeroing), which one thread does alone when the storage is then value-initialized or copied
/// into in order. For a buffer about to be overwritten, such as a vector's reserved capacity
/// before resize(): nothing it held is kept.
inline void prefaultPages(void* p, std::size_t bytes, bool threaded)
{
    constexpr std::size_t kPage = 4096, kBlock = std::size_t(2) << 20;
    if (!p || bytes == 0) return;
    char* base = static_cast<char*>(p);
    forEachIndex((bytes + kBlock - 1) / kBlock, threaded, [&](std::size_t b) {
        const std::size_t end = std::min(bytes, (b + 1) * kBlock);
        for (std::size_t at = b * kBlock; at < end; at += kPage) base[at] = 0;
    }, 1);
}

} // namespace vdbhair
