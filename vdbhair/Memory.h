/// @file Memory.h
/// @brief Large buffers that fill fast: a hint for transparent huge pages.
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

#include <algorithm>
#include <cstddef>
#include <cstdint>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace vdbhair {

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
