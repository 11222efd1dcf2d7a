/// @file Simd.h
/// @brief Small SIMD and memory helpers shared by the field kernels (estimation and tracing).
///
/// Float4 is a GCC/Clang vector extension: four floats operated on as one SIMD value, compiled
/// to SSE on x86-64 and NEON on ARM, or to scalar code on targets without SIMD. No intrinsics
/// headers: the one target builtin (sqrt4) is guarded, with a portable fallback.
#pragma once

#include <cstddef>

namespace vdbhair {

/// Four floats as one SIMD value (see the file comment).
typedef float Float4 __attribute__((vector_size(16)));
/// Four ints; also the lane masks that comparisons of Float4 values give (-1 true, 0 false).
typedef int Int4 __attribute__((vector_size(16)));
/// Four unsigned ints (unsigned comparisons).
typedef unsigned UInt4 __attribute__((vector_size(16)));
/// Eight floats: two Float4 side by side. One AVX register in code compiled for AVX (the
/// tracer's AVX2 clone), two SSE registers elsewhere, with the same results either way.
typedef float Float8 __attribute__((vector_size(32)));

// Float8 helpers are always inlined, so passing one by value never crosses a call: GCC's note
// that the SSE and AVX calling conventions differ for 32-byte vectors does not apply.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"

/// @brief The two Float4 at @a p (p[0] in the low half): one unaligned load.
__attribute__((always_inline)) inline Float8 loadPair(const Float4* p)
{
    Float8 v;
    __builtin_memcpy(&v, p, sizeof v);
    return v;
}

/// @brief The low (p[0] of loadPair) and high halves of @a v.
__attribute__((always_inline)) inline Float4 lowHalf(const Float8& v)
{
    Float4 r;
    __builtin_memcpy(&r, &v, sizeof r);
    return r;
}
__attribute__((always_inline)) inline Float4 highHalf(const Float8& v)
{
    Float4 r;
    __builtin_memcpy(&r, reinterpret_cast<const char*>(&v) + sizeof r, sizeof r);
    return r;
}

#pragma GCC diagnostic pop

/// @brief Lanes (A, B, C, D) of the eight lanes of @a a (0-3) and @a b (4-7).
template<int A, int B, int C, int D>
inline Float4 shuffle(const Float4& a, const Float4& b)
{
#if defined(__clang__)
    return __builtin_shufflevector(a, b, A, B, C, D);
#else
    return __builtin_shuffle(a, b, Int4{A, B, C, D});
#endif
}

/// @brief Transpose the 4×4 matrix whose rows are r0..r3, in place.
inline void transpose(Float4& r0, Float4& r1, Float4& r2, Float4& r3)
{
    const Float4 t0 = shuffle<0, 4, 1, 5>(r0, r1), t1 = shuffle<0, 4, 1, 5>(r2, r3);
    const Float4 t2 = shuffle<2, 6, 3, 7>(r0, r1), t3 = shuffle<2, 6, 3, 7>(r2, r3);
    r0 = shuffle<0, 1, 4, 5>(t0, t1);
    r1 = shuffle<2, 3, 6, 7>(t0, t1);
    r2 = shuffle<0, 1, 4, 5>(t2, t3);
    r3 = shuffle<2, 3, 6, 7>(t2, t3);
}

/// @brief Square roots of the four lanes (one instruction with SSE, four elsewhere).
inline Float4 sqrt4(const Float4& x)
{
#if defined(__GNUC__) && defined(__SSE__)
    return __builtin_ia32_sqrtps(x);
#else
    return Float4{__builtin_sqrtf(x[0]), __builtin_sqrtf(x[1]), __builtin_sqrtf(x[2]), __builtin_sqrtf(x[3])};
#endif
}

/// @brief @a mask ? @a a : @a b, lane by lane (@a mask from a comparison: -1 or 0 per lane).
inline Float4 select(const Int4& mask, const Float4& a, const Float4& b)
{
    return (Float4)((mask & (Int4)a) | (~mask & (Int4)b));
}

/// @brief The larger of @a a and @a b, lane by lane, as unsigned ints.
inline UInt4 maxU(const UInt4& a, const UInt4& b) { return a > b ? a : b; }

/// @brief Store @a v at @a p (16 bytes, aligned).
inline void storeFloat4(float* p, const Float4& v) { __builtin_memcpy(p, &v, sizeof v); }
inline void storeInt4(int* p, const Int4& v) { __builtin_memcpy(p, &v, sizeof v); }

/// @brief Whether any lane of the mask is set.
inline bool any(const Int4& mask)
{
    typedef long long Long2 __attribute__((vector_size(16)));
    const Long2 m = (Long2)mask;
    return (m[0] | m[1]) != 0;
}

/// @brief The lanes set in @a mask as bits 0-3.
inline unsigned bits(const Int4& mask)
{
    return unsigned(mask[0] & 1) | unsigned(mask[1] & 2) | unsigned(mask[2] & 4) | unsigned(mask[3] & 8);
}

/// @brief The three floats at @a p as a Float4 with w = 0 (no read past them).
inline Float4 loadFloat3(const float* p)
{
    return Float4{p[0], p[1], p[2], 0.f};
}

/// @brief Ask the processor to bring the cache lines of [first, first + bytes) closer; @a Write
/// (0 or 1) says whether they are about to be written. A hint only: no effect on results.
///
/// Both the field estimation and the tracer visit strands in spatial order, which scatters them
/// over memory: each new strand starts with cache misses that the hardware prefetcher cannot
/// foresee. Asking for a later strand while the current one is processed hides that latency.
/// @note Always inlined on purpose: GCC finds a function whose only effect is a prefetch to be
/// "pure", and then deletes calls to it, since they return nothing.
template<int Write = 0>
__attribute__((always_inline)) inline void prefetchBytes(const void* first, std::size_t bytes)
{
    const char* p = static_cast<const char*>(first);
    for (std::size_t off = 0; off < bytes; off += 64) __builtin_prefetch(p + off, Write, 3);
}

} // namespace vdbhair
