/// @file LaneTracer.h
/// @brief The fast path of the streamline engine (Streamline.h) for retraceStrands(): forward
/// Euler through a vector grid, eight streamlines at a time in SIMD lanes, with the x86-64
/// baseline and AVX2 clones of its loop. Included by StreamlineTracer.cc only.
#pragma once

#include <vdbhair/Exceptions.h>
#include <vdbhair/Memory.h>
#include <vdbhair/Progress.h>
#include <vdbhair/field/FieldMapping.h>
#include <vdbhair/field/FieldSampler.h>
#include <vdbhair/field/Simd.h>
#include <vdbhair/field/Streamline.h>
#include <vdbhair/strands/StrandSet.h>

#if defined(__linux__)
#include <sys/mman.h>  // madvise
#endif

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <thread>
#include <vector>

namespace vdbhair {
namespace lanes {

using openvdb::Vec3d;

/// @brief What the threads of one retrace share: inputs, outputs written per strand, and the
/// hand-out of strands.
///
/// Strands are handed out in blocks, in index order, to whichever thread asks next (a strand's
/// result does not depend on the thread that traces it, so any hand-out gives the same output).
/// In input mode the output vector is built while the strands are traced: mapping and zeroing
/// tens of megabytes of fresh pages costs about a fifth of the tracing and does not get faster
/// with more threads (the page faults serialize), so one task grows the vector piece by piece
/// while the other threads trace, and a strand is written out once the vector covers it. In
/// index order both the input and the output are walked front to back, so the tracers rarely
/// wait.
template<typename TreeT>
struct RetraceJob
{
    static constexpr std::size_t kBlock = 256;  ///< strands per hand-out
    static constexpr std::size_t kPiece = std::size_t(1) << 17;  ///< vertices per growth step

    const StrandSet& in;
    const TraceParams& params;
    double step;
    const FieldMapping& map;
    std::vector<Vec3f>* output;               ///< input mode: the output positions (else nullptr)
    std::vector<std::uint32_t>& used;         ///< input mode: vertices each strand keeps
    std::vector<std::vector<Vec3f>>& stepPoints;  ///< step mode: each strand's points
    std::vector<StopReason>& reasons;
    std::vector<std::size_t>& steps;
    ProgressCounter& progress;                ///< counts strands as they are handed out
    std::atomic<bool> stop{false};
    std::atomic<std::size_t> nextBlock{0};
    std::atomic<std::size_t> ready{0};  ///< elements of *output constructed so far
    std::atomic<bool> growing{false}, failed{false};

    /// @brief The next block [begin, end) of strands to trace; false when none is left.
    bool nextRange(std::size_t& begin, std::size_t& end)
    {
        const std::size_t nS = in.numStrands();
        if (stop.load(std::memory_order_relaxed)) return false;
        const std::size_t first = nextBlock.fetch_add(1, std::memory_order_relaxed) * kBlock;
        if (first >= nS) return false;
        begin = first;
        end = std::min(nS, first + kBlock);
        if (progress.add(end - begin)) {
            stop = true;
            return false;
        }
        return true;
    }

    /// @brief Grow *output to the input's vertex count, publishing each piece in ready: the
    /// first caller does it all, later calls return at once. *output's capacity is reserved
    /// beforehand, so its storage never moves and tracers may write the published part.
    void growOutput()
    {
        if (!output || growing.exchange(true)) return;
        try {
            const std::size_t n = in.numVertices();
            ready.store(output->size(), std::memory_order_release);  // a reused output's elements
            for (std::size_t size = output->size(); size < n;) {
                const std::size_t from = size;
                size = std::min(n, size + kPiece);
#if defined(__linux__) && defined(MADV_POPULATE_WRITE)
                // Map the piece's whole pages in one system call rather than one fault per page
                // (a hint: contents are untouched, and older kernels just refuse it).
                const std::uintptr_t lo = (reinterpret_cast<std::uintptr_t>(output->data() + from) + 4095) & ~std::uintptr_t(4095);
                const std::uintptr_t hi = reinterpret_cast<std::uintptr_t>(output->data() + size) & ~std::uintptr_t(4095);
                if (hi > lo) madvise(reinterpret_cast<void*>(lo), hi - lo, MADV_POPULATE_WRITE);
#else
                (void)from;
#endif
                output->resize(size);
                ready.store(size, std::memory_order_release);
            }
        } catch (...) {
            failed = true;
            stop = true;
            throw;
        }
    }

    /// @brief Wait until *output covers [0, end), growing it if nobody does yet.
    /// @return false if growing it failed.
    bool waitForOutput(std::size_t end)
    {
        while (ready.load(std::memory_order_acquire) < end) {
            if (failed) return false;
            growOutput();
            std::this_thread::yield();
        }
        return true;
    }
};

/// @brief Traces strands kLanes at a time, taking blocks of strands from a RetraceJob; one per thread.
///
/// A step is a chain of dependent operations (map, sample, normalize, move): on its own a
/// streamline leaves the processor mostly waiting. Independent lanes, one step of each in turn,
/// let it overlap their chains, provided the loop over the lanes stays short and its branches
/// predictable. So fastRound() does only the common case — a forward Euler step in an
/// axis-aligned world grid, inside a brick, where the field neither vanishes nor ends — and
/// merely flags a lane for everything else: the strand is done, or its step needs the engine's
/// general step (RK2/RK4, scalp space, cells outside the bricks, the margin past the active region, a
/// vanishing field). A lane only records its step points; the arc-length bookkeeping (output
/// vertices at the input's arc lengths) happens once per strand, in finish(). Step m lies at arc
/// length m·step along the streamline (the integrators move at unit speed), the last step being
/// shortened to land on the strand's length.
///
/// In the fast path a lane's position is its brick's origin (integers) plus a float offset in
/// [0, 8)³: floats that small resolve 2⁻²¹ voxel wherever the grid lies, and the cell, the
/// trilinear fractions, the step and the test for leaving the brick are then a few SIMD
/// operations. Lanes go in groups of four, one SIMD lane each (a Group holds x, y, z of four
/// lanes in three Float4): only the brick lookups and blends are per lane; normalizing, testing,
/// stepping and storing the step points are done for four lanes at once. Step points are kept
/// relative to the strand's first brick and become world positions in finish().
///
/// The whole loop — steps, strand starts (arc lengths) and write-outs — is compiled twice, for
/// the x86-64 baseline and for AVX2, and run() picks by the processor: in the AVX2 clone a blend
/// is nine 8-float operations on pairs of corners instead of eighteen 4-float ones (FieldSampler.h).
/// Neither clone contracts to FMA (ISO C++ mode), so both give the same floats.
///
/// Every step that is not the fast path's goes through the streamline engine
/// (StreamlineIntegrator over a FieldDirectionSampler, and its margin rule continuesPastField()):
/// the lanes differ from the general path (traceStreamline()) only in float rounding, which a
/// seeded property test bounds (tests/field/TestStreamlineTracer.cc).
template<typename TreeT>
class LaneTracer
{
public:
    using Bricks = BrickedField<TreeT>;
    using Brick = typename Bricks::Brick;
    static constexpr int kGroups = 2;
    static constexpr int kLanes = 4 * kGroups;
    static constexpr int N = Bricks::N;

    using Sampler = FieldDirectionSampler<TreeT>;

    LaneTracer(RetraceJob<TreeT>& job, const Bricks& bricks)
        : mJob(job), mBricks(bricks), mSampler(bricks, job.map, job.params.vanishThreshold),
          mIntegrator(mSampler, job.params.integrator),
          mFast(job.params.integrator == Integrator::Euler && job.map.isAxisAlignedWorld()),
          mInputMode(job.params.vertices == RetraceVertices::Input), mStep(job.step),
          mThreshold2(float(job.params.vanishThreshold) * float(job.params.vanishThreshold)),
          mMarginLength(double(job.params.margin) * job.map.worldVoxelSize())
    {
        if (mFast) {
            mOff = job.map.offset();
            mInv = job.map.invScale();
            mScale = Vec3d(1.0 / mInv.x(), 1.0 / mInv.y(), 1.0 / mInv.z());
        }
        mStepScale = Float4{float(mStep * mInv.x()), float(mStep * mInv.y()), float(mStep * mInv.z()), 0.f};
        for (int l = 0; l < kLanes; ++l) idle(l);
    }

    /// Whether this processor runs the AVX2 clone of the loop.
    static bool haveAvx2()
    {
#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__))
        return __builtin_cpu_supports("avx2");
#else
        return false;
#endif
    }

    /// @brief Trace strands until the job has none left: with the AVX2 clone of the loop where
    /// the processor has AVX2 (the blends then take half the operations; no FMA, so the results
    /// are the same as the SSE loop's), or the clone @a kernel forces (TraceKernel::LanesSse,
    /// LanesAvx2; the caller checks haveAvx2() first).
    void run(TraceKernel kernel = TraceKernel::Auto)
    {
#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__))
        if (kernel == TraceKernel::LanesAvx2 || (kernel == TraceKernel::Auto && haveAvx2())) return runAvx2();
#else
        (void)kernel;
#endif
        runLoop();
    }

private:
#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__))
    __attribute__((target("avx2"))) void runAvx2() { runLoop(); }
#endif

    __attribute__((always_inline)) void runLoop()
    {
        for (int l = 0; l < kLanes; ++l) start(l);
        while (mBusy > 0) {
            for (int g = 0; g < kGroups; ++g) {
                for (unsigned flagged = mFast ? fastRound(mGroups[g]) : 0xfu; flagged; flagged &= flagged - 1) {
                    const int e = flagged & 1u ? 0 : flagged & 2u ? 1 : flagged & 4u ? 2 : 3;
                    handle(4 * g + e);
                }
            }
        }
    }

    /// Four lanes' fast-path state, one SIMD lane each.
    struct Group
    {
        Float4 lx, ly, lz;  ///< index position minus the lane's base, in [0, 8)
        Float4 rx, ry, rz;  ///< the lane's base minus its origin
        Float4 sx, sy, sz;  ///< index units of this step per unit of world direction
        Int4 k;             ///< steps taken
        Int4 fastEnd;       ///< fastRound() steps while k < fastEnd
        const Brick* brick[4];  ///< the brick at the lane's base (the zero brick if no leaf)
        Float4* pts[4];         ///< the lane's step points
    };

    /// A lane's other state.
    struct Lane
    {
        bool busy = false;
        bool far = false;           ///< beyond the grid's index range: every step is a slow one
        int base[3] = {0, 0, 0};    ///< origin of the brick of the position (multiples of 8)
        int origin[3] = {0, 0, 0};  ///< base of the root: step points are relative to it
        Vec3d p{0.0};               ///< world position, where base and offset do not hold it (!mFast, far)
        int limit = 0;              ///< steps allowed: needed, or fewer under maxSteps
        int needed = 0;             ///< steps to the full length
        double lastStep = 0.0;      ///< length of the last step, step needed - 1
        Vec3d dir{0.0};             ///< unit direction of step dirAt - 1 -> dirAt, if a slow one
        int dirAt = -1;
        double outside = 0.0;       ///< length travelled in a row past the active region, up to step outsideAt
        int outsideAt = -1;
        std::size_t strand = 0;
        double length = 0.0;
        std::vector<double> target;  ///< the input's vertex arc lengths
        std::vector<Float4> points;  ///< points[m] at arc length m·step (points[needed]: the length)
    };

    // Lane l is element l & 3 of group l >> 2.
    Group& group(int l) { return mGroups[l >> 2]; }
    int kOf(int l) { return group(l).k[l & 3]; }
    Float4 pointOf(int l, int m) { return group(l).pts[l & 3][m]; }

    /// @brief One forward Euler step of each lane of @a G that can take it without help.
    /// @return the lanes that did not step (bits 0-3): done, idle, or needing handle().
    __attribute__((always_inline)) unsigned fastRound(Group& G)
    {
        // The sampling cells and the fractions within them: offsets are >= 0, so truncation floors.
        const Float4 cx = __builtin_convertvector(__builtin_convertvector(G.lx, Int4), Float4);
        const Float4 cy = __builtin_convertvector(__builtin_convertvector(G.ly, Int4), Float4);
        const Float4 cz = __builtin_convertvector(__builtin_convertvector(G.lz, Int4), Float4);
        // Each lane's blend takes its fractions from memory: the compiler broadcasts them with
        // one load each rather than shuffling lanes out of a register.
        alignas(16) float f[3][4];
        alignas(16) int cell[4];
        storeFloat4(f[0], G.lx - cx);
        storeFloat4(f[1], G.ly - cy);
        storeFloat4(f[2], G.lz - cz);
        storeInt4(cell, __builtin_convertvector(cx * float(N * N) + cy * float(N) + cz, Int4));  // exact: small integers
        Float4 vx = Bricks::blend(G.brick[0]->cell + cell[0], f[0][0], f[1][0], f[2][0]);
        Float4 vy = Bricks::blend(G.brick[1]->cell + cell[1], f[0][1], f[1][1], f[2][1]);
        Float4 vz = Bricks::blend(G.brick[2]->cell + cell[2], f[0][2], f[1][2], f[2][2]);
        Float4 vw = Bricks::blend(G.brick[3]->cell + cell[3], f[0][3], f[1][3], f[2][3]);
        transpose(vx, vy, vz, vw);  // now x, y, z, w of the four lanes
        // Vanishing (|v| <= threshold · w) or outside (w = 0: no active corner, and then v = 0
        // too, as inactive corners hold zero vectors) fail the one test len2 > threshold² w².
        const Float4 len2 = vx * vx + vy * vy + vz * vz;
        const Int4 ok = (len2 > mThreshold2 * (vw * vw)) & (G.k < G.fastEnd);
        const Float4 s = 1.f / sqrt4(len2);  // inf or NaN in failing lanes, which keep their state
        G.lx = select(ok, G.lx + vx * s * G.sx, G.lx);
        G.ly = select(ok, G.ly + vy * s * G.sy, G.ly);
        G.lz = select(ok, G.lz + vz * s * G.sz, G.lz);
        G.k -= ok;  // ok is -1 where true
        // The new step points.
        Float4 p[4] = {G.lx + G.rx, G.ly + G.ry, G.lz + G.rz, {0.f, 0.f, 0.f, 0.f}};
        transpose(p[0], p[1], p[2], p[3]);
        const Int4 failed = ~ok;
        if (__builtin_expect(!any(failed), 1)) {
            for (int e = 0; e < 4; ++e) G.pts[e][G.k[e]] = p[e];
        } else {
            for (int e = 0; e < 4; ++e) if (ok[e]) G.pts[e][G.k[e]] = p[e];
        }
        // Out of the brick (or not a number, from a field holding infinities): move the base
        // (rare, and well predicted).
        // A float is in [0, 8) exactly when its bits, read as unsigned, are below those of 8.0f
        // (negative floats have the sign bit, NaNs the all-ones exponent): one test for all three.
        const UInt4 bx = (UInt4)G.lx, by = (UInt4)G.ly, bz = (UInt4)G.lz;
        const UInt4 bmax = maxU(maxU(bx, by), bz);
        const Int4 out = (Int4)(bmax >= UInt4{kBitsOf8, kBitsOf8, kBitsOf8, kBitsOf8});
        if (__builtin_expect(any(out), 0)) {
            for (int e = 0; e < 4; ++e) if (out[e]) rebase(4 * int(&G - mGroups) + e);
        }
        // The cells of the next round, far apart in memory: fetch them while the other group steps.
        const Float4 nx = __builtin_convertvector(__builtin_convertvector(G.lx, Int4), Float4);
        const Float4 ny = __builtin_convertvector(__builtin_convertvector(G.ly, Int4), Float4);
        const Float4 nz = __builtin_convertvector(__builtin_convertvector(G.lz, Int4), Float4);
        const Int4 next = __builtin_convertvector(nx * float(N * N) + ny * float(N) + nz, Int4);
        for (int e = 0; e < 4; ++e) {
            const Float4* c = G.brick[e]->cell + next[e];
            __builtin_prefetch(c);
            __builtin_prefetch(c + N);
            __builtin_prefetch(c + N * N);
            __builtin_prefetch(c + N * N + N);
        }
        return any(failed) ? bits(failed) : 0u;
    }

    /// A flagged lane: finish its strand, let it take its shortened last step fast, or step slowly.
    __attribute__((always_inline)) void handle(int l)
    {
        Lane& L = mLanes[l];
        if (!L.busy) return;
        Group& G = group(l);
        const int e = l & 3, k = G.k[e];
        if (k == L.limit) {
            finish(l, L.limit == L.needed ? StopReason::FullLength : StopReason::MaxSteps);
        } else if (mFast && !L.far && k == G.fastEnd[e] && k + 1 == L.needed) {
            // The last, shortened step: the fast path takes it too, at its own length.
            G.sx[e] = float(L.lastStep * mInv.x());
            G.sy[e] = float(L.lastStep * mInv.y());
            G.sz[e] = float(L.lastStep * mInv.z());
            G.fastEnd[e] = L.needed;
        } else {
            slowStep(l);
        }
    }

    /// Move lane l's base to the brick its offset has entered.
    __attribute__((always_inline)) void rebase(int l)
    {
        Lane& L = mLanes[l];
        Group& G = group(l);
        const int e = l & 3;
        const float local[3] = {G.lx[e], G.ly[e], G.lz[e]};
        int b[3];
        bool far = false;
        if (std::abs(local[0] - 4.f) < 12.f && std::abs(local[1] - 4.f) < 12.f && std::abs(local[2] - 4.f) < 12.f) {
            // The common case: the step left the brick by less than a brick (local in (-8, 16)):
            // the base moves by -8, 0 or +8 on each axis, and the offsets by exact small integers.
            for (int a = 0; a < 3; ++a) b[a] = L.base[a] + 8 * (int(local[a] >= 8.f) - int(local[a] < 0.f));
        } else {
            for (int a = 0; a < 3 && !far; ++a) {
                far = !(std::abs(double(local[a])) < kFar);  // a huge step, or NaN
                if (!far) b[a] = L.base[a] + 8 * floorToInt(double(local[a]) * 0.125);
            }
        }
        // |b| < kFar on every axis, as one unsigned test each.
        constexpr std::uint32_t kFarI = std::uint32_t(kFar);
        for (int a = 0; a < 3 && !far; ++a) far = !(std::uint32_t(b[a]) + (kFarI - 1) < 2 * kFarI - 1);
        if (far) {
            goFar(l, worldOf(l));
            return;
        }
        G.lx[e] = clampLocal(local[0] - float(b[0] - L.base[0]));  // exact: small integers
        G.ly[e] = clampLocal(local[1] - float(b[1] - L.base[1]));
        G.lz[e] = clampLocal(local[2] - float(b[2] - L.base[2]));
        setBase(l, b);
    }

    /// Set lane l's base (and its brick and offset from the origin).
    __attribute__((always_inline)) void setBase(int l, const int* b)
    {
        Lane& L = mLanes[l];
        Group& G = group(l);
        const int e = l & 3;
        for (int a = 0; a < 3; ++a) L.base[a] = b[a];
        G.rx[e] = float(b[0] - L.origin[0]);
        G.ry[e] = float(b[1] - L.origin[1]);
        G.rz[e] = float(b[2] - L.origin[2]);
        G.brick[e] = mBricks.brickAt(b[0] >> 3, b[1] >> 3, b[2] >> 3);
    }

    /// A float offset within a brick: [0, 8), even where rounding reached 8.
    static float clampLocal(float x) { return std::min(7.9999995f, std::max(0.f, x)); }

    /// Index coordinates from here on do not fit base + offset: trace on in world space.
    void goFar(int l, const Vec3d& world)
    {
        Lane& L = mLanes[l];
        Group& G = group(l);
        L.far = true;
        L.p = world;
        G.fastEnd[l & 3] = 0;
        G.lx[l & 3] = G.ly[l & 3] = G.lz[l & 3] = 0.f;  // a harmless cell for fastRound()
    }

    /// Lane l's world position (double).
    Vec3d worldOf(int l)
    {
        const Lane& L = mLanes[l];
        if (!mFast || L.far) return L.p;
        const Group& G = group(l);
        const int e = l & 3;
        return Vec3d(mOff.x() + (double(L.base[0]) + double(G.lx[e])) * mScale.x(),
                     mOff.y() + (double(L.base[1]) + double(G.ly[e])) * mScale.y(),
                     mOff.z() + (double(L.base[2]) + double(G.lz[e])) * mScale.z());
    }

    /// @brief Put lane l at world position @a q after step k (a new strand's root when k == 0):
    /// its base, offset and brick, and step point k.
    __attribute__((always_inline)) void place(int l, const Vec3d& q)
    {
        Lane& L = mLanes[l];
        Group& G = group(l);
        const int e = l & 3, k = G.k[e];
        if (!mFast) {
            L.p = q;
            G.pts[e][k] = Float4{float(q.x()), float(q.y()), float(q.z()), 0.f};
            return;
        }
        const Vec3d ip = (q - mOff) * mInv;
        if (L.far || !(std::abs(ip.x()) < kFar && std::abs(ip.y()) < kFar && std::abs(ip.z()) < kFar)) {
            goFar(l, q);
            G.pts[e][k] = Float4{float(ip.x() - L.origin[0]), float(ip.y() - L.origin[1]), float(ip.z() - L.origin[2]), 0.f};
            return;
        }
        int b[3];
        for (int a = 0; a < 3; ++a) {
            b[a] = floorToInt(ip[a]) & ~7;
            if (k == 0) L.origin[a] = b[a];
        }
        G.lx[e] = clampLocal(float(ip.x() - double(b[0])));
        G.ly[e] = clampLocal(float(ip.y() - double(b[1])));
        G.lz[e] = clampLocal(float(ip.z() - double(b[2])));
        setBase(l, b);
        // Fast steps up to the last, shortened one (see handle()).
        G.sx[e] = mStepScale[0];
        G.sy[e] = mStepScale[1];
        G.sz[e] = mStepScale[2];
        G.fastEnd[e] = std::min(L.limit, L.needed - (L.needed > 0));
        G.pts[e][k] = Float4{float(ip.x() - L.origin[0]), float(ip.y() - L.origin[1]), float(ip.z() - L.origin[2]), 0.f};
    }

    /// The unit world direction of lane l's last step (k - 1 -> k, k > 0).
    Vec3d lastDirection(int l)
    {
        const Lane& L = mLanes[l];
        const int k = kOf(l);
        if (L.dirAt == k) return L.dir;
        // A fast step: from its step points (index units relative to the origin).
        const Float4 d = pointOf(l, k) - pointOf(l, k - 1);
        const Vec3d w = mFast ? Vec3d(d[0] * mScale.x(), d[1] * mScale.y(), d[2] * mScale.z()) : Vec3d(d[0], d[1], d[2]);
        const double len = w.length();
        return len > 0.0 ? w / len : Vec3d(0.0);
    }

    /// Any step of lane @a l through the streamline engine; finishes the strand if it stops.
    void slowStep(int l)
    {
        Lane& L = mLanes[l];
        const int k = kOf(l);
        const double h = k + 1 == L.needed ? L.lastStep : mStep;
        const Vec3d p = worldOf(l);
        Vec3d q;
        const SampleStatus st = mIntegrator.advance(p, h, q);
        if (st == SampleStatus::Ok) {
            L.dir = (q - p) / h;
            L.dirAt = k + 1;
        } else if (const double outside = L.outsideAt == k ? L.outside : 0.0;
                   continuesPastField(st, std::size_t(k), outside, h, mMarginLength)) {
            // Past the active region, within the margin: continue straight.
            L.dir = lastDirection(l);
            L.dirAt = k + 1;
            q = p + h * L.dir;
            L.outside = outside + h;
            L.outsideAt = k + 1;
        } else {
            finish(l, stopReasonOf(st));
            return;
        }
        group(l).k[l & 3] = k + 1;
        place(l, q);
    }

    /// Lane l without a strand: fastRound() flags it every round, handle() ignores it.
    void idle(int l)
    {
        Lane& L = mLanes[l];
        Group& G = group(l);
        const int e = l & 3;
        L.busy = false;
        if (L.points.empty()) L.points.resize(1);
        G.pts[e] = L.points.data();
        G.k[e] = G.fastEnd[e] = 0;
        G.lx[e] = G.ly[e] = G.lz[e] = 0.f;
        G.rx[e] = G.ry[e] = G.rz[e] = 0.f;
        G.sx[e] = G.sy[e] = G.sz[e] = 0.f;
        G.brick[e] = mBricks.brickAt(std::numeric_limits<int>::min() >> 3, 0, 0);  // the zero brick
    }

    /// @brief Start the next strand in lane l, or leave it idle if there is none (or the
    /// retrace was interrupted).
    __attribute__((always_inline)) void start(int l)
    {
        RetraceJob<TreeT>& job = mJob;
        Lane& L = mLanes[l];
        const bool was = L.busy;
        const bool next = mNext < mEnd || job.nextRange(mNext, mEnd);
        if (!next) {
            idle(l);
            mBusy -= was;
            return;
        }
        mBusy += !was;
        const std::size_t i = mNext++;
        const StrandSet& in = job.in;
        const std::size_t n = in.size(i);
        // Lanes start strands far apart in time: fetch a later strand's vertices meanwhile.
        if (mNext + kAhead < mEnd) prefetchBytes(in.data(mNext + kAhead), in.size(mNext + kAhead) * sizeof(Vec3f));
        L.target.resize(n);
        L.length = arcLengthsF(in.data(i), n, L.target.data());
        if (!std::isfinite(L.length)) L.length = 0.0;  // vertices at infinity: not traced
        // Whole steps, the last one shortened to land on the length (none for zero length).
        const double needed = L.length > 0.0 ? std::max(1.0, std::ceil(L.length / mStep - 1e-9)) : 0.0;
        const double limit = job.params.maxSteps ? std::min(needed, double(job.params.maxSteps)) : needed;
        if (!(limit < double(kMaxSteps))) {
            job.stop = true;
            throw LimitError("retraceStrands: strand " + std::to_string(i) + " would take " + std::to_string(limit) +
                             " steps, more than " + std::to_string(kMaxSteps) + " (raise the step or set a step cap)");
        }
        L.needed = int(needed);
        L.limit = int(limit);
        L.lastStep = L.needed ? L.length - double(L.needed - 1) * mStep : 0.0;
        L.strand = i;
        L.busy = true;
        L.far = false;
        L.dirAt = L.outsideAt = -1;
        if (L.points.size() < std::size_t(L.limit) + 1) L.points.resize(std::size_t(L.limit) + 1);
        Group& G = group(l);
        G.pts[l & 3] = L.points.data();
        G.k[l & 3] = 0;
        place(l, Vec3d(in.root(i)));
    }

    /// @brief retraceArcLengths() (Streamline.h): segment lengths in float, summed in double.
    /// Four segments at a time: the twelve floats of points j..j+3 minus those of j-1..j+2 are
    /// the four segments' components, regrouped by shuffles into x, y and z; each length is the
    /// same float operations as one segment at a time ((dx² + dy²) + dz², then its square root),
    /// and the sum runs in the same order, so the result is the scalar loop's, bit for bit.
    /// @return the strand's length.
    __attribute__((always_inline)) static double arcLengthsF(const Vec3f* v, std::size_t n, double* out)
    {
        double s = 0.0;
        out[0] = 0.0;
        std::size_t j = 1;
        const float* f = v[0].asPointer();
        for (; j + 3 < n; j += 4) {
            Float4 a0, a1, a2, b0, b1, b2;
            __builtin_memcpy(&a0, f + 3 * j, 16);
            __builtin_memcpy(&a1, f + 3 * j + 4, 16);
            __builtin_memcpy(&a2, f + 3 * j + 8, 16);
            __builtin_memcpy(&b0, f + 3 * j - 3, 16);
            __builtin_memcpy(&b1, f + 3 * j + 1, 16);
            __builtin_memcpy(&b2, f + 3 * j + 5, 16);
            const Float4 d0 = a0 - b0, d1 = a1 - b1, d2 = a2 - b2;  // x0 y0 z0 x1 | y1 z1 x2 y2 | z2 x3 y3 z3
            const Float4 q0 = d0 * d0, q1 = d1 * d1, q2 = d2 * d2;
            const Float4 x = Float4{q0[0], q0[3], q1[2], q2[1]};
            const Float4 y = Float4{q0[1], q1[0], q1[3], q2[2]};
            const Float4 z = Float4{q0[2], q1[1], q2[0], q2[3]};
            const Float4 len = sqrt4(x + y + z);
            s += double(len[0]);
            out[j] = s;
            s += double(len[1]);
            out[j + 1] = s;
            s += double(len[2]);
            out[j + 2] = s;
            s += double(len[3]);
            out[j + 3] = s;
        }
        for (; j < n; ++j) {
            const float dx = v[j].x() - v[j - 1].x(), dy = v[j].y() - v[j - 1].y(), dz = v[j].z() - v[j - 1].z();
            s += double(std::sqrt(dx * dx + dy * dy + dz * dz));
            out[j] = s;
        }
        return s;
    }

    /// Write lane @a l's strand out and start the next strand in the lane (or idle it).
    __attribute__((always_inline)) void finish(int l, StopReason reason)
    {
        Lane& L = mLanes[l];
        RetraceJob<TreeT>& job = mJob;
        const std::size_t i = L.strand;
        const Float4* pts = group(l).pts[l & 3];  // pts[0 .. taken]
        const std::size_t taken = std::size_t(kOf(l));
        // Step points are index positions relative to origin (world positions if !mFast): small
        // numbers, so the world position of origin, rounded to float once, plus a point times
        // the voxel size loses about one float rounding more than a double computation would.
        const Vec3d o = mFast ? mOff + Vec3d(L.origin[0], L.origin[1], L.origin[2]) * mScale : Vec3d(0.0);
        const Float4 o4 = {float(o.x()), float(o.y()), float(o.z()), 0.f};
        const Float4 s4 = mFast ? Float4{float(mScale.x()), float(mScale.y()), float(mScale.z()), 0.f} : Float4{1.f, 1.f, 1.f, 0.f};
        auto world = [&](const Float4& p) {
            const Float4 w = o4 + p * s4;
            return Vec3f(w[0], w[1], w[2]);
        };
        // Output vertex u of @a count from step point p: all four floats of the world position
        // in one store where the next vertex (of this strand, written later) takes the fourth.
        auto emit = [&](Vec3f* out, std::size_t u, std::size_t count, const Float4& p) {
            if (u + 1 == count) {
                out[u] = world(p);
                return;
            }
            const Float4 w = o4 + p * s4;
            __builtin_memcpy(out[u].asPointer(), &w, sizeof w);
        };
        const Vec3f root = job.in.root(i);
        if (!mInputMode) {
            std::vector<Vec3f>& sp = job.stepPoints[i];
            sp.resize(taken + 1);
            sp[0] = root;
            for (std::size_t m = 1; m <= taken; ++m) sp[m] = world(pts[m]);
            if (taken == 0) sp.push_back(root);
        } else if (job.waitForOutput(job.in.end(i))) {
            const std::size_t n = job.in.size(i);
            const double* target = L.target.data();
            const std::size_t needed = std::size_t(L.needed);
            const double reached = taken == needed ? L.length : double(taken) * mStep;
            Vec3f* out = job.output->data() + job.in.begin(i);
            out[0] = root;  // target[0] = 0: the root, exactly
            std::size_t u = 1;
            if (taken > 0) {
                // Vertices on whole steps: step m spans [m·step, (m+1)·step]. The last step of
                // a full-length trace is shorter; vertices on it are placed separately.
                const bool shortLast = taken == needed;
                const std::size_t whole = shortLast ? taken - 1 : taken;
                const int mMax = int(whole - (whole > 0));  // steps are below 2^31 (kMaxSteps)
                const double wholeEnd = double(whole) * mStep, invStep = 1.0 / mStep;
                std::size_t j = 1;
                for (; j < n && target[j] <= wholeEnd; ++j) {
                    const double x = target[j] * invStep;  // >= 0: truncation floors
                    const int m = std::min(int(x), mMax);
                    const float t = float(x - double(m));
                    emit(out, u++, n, pts[m] + (pts[m + 1] - pts[m]) * t);
                }
                for (; j < n && target[j] <= reached; ++j) {  // on the last, shorter step
                    const float t = float(std::min(1.0, (target[j] - wholeEnd) / L.lastStep));
                    emit(out, u++, n, pts[whole] + (pts[whole + 1] - pts[whole]) * t);
                }
            }
            const Vec3f last = taken == 0 ? root : world(pts[taken]);
            if (reason == StopReason::FullLength) {
                out[n - 1] = last;  // exactly the traced tip
            } else {
                // Keep what was traced: the vertices passed, then the point where it stopped
                // (fewer than n vertices, since the length was not reached), at least two.
                if (out[u - 1] != last) out[u++] = last;
                if (u < 2) out[u++] = last;
            }
            job.used[i] = std::uint32_t(u);
        }
        job.reasons[i] = reason;
        job.steps[i] = taken;
        start(l);
    }

    /// The bits of 8.0f (see fastRound()).
    static constexpr unsigned kBitsOf8 = 0x41000000u;
    /// Index coordinates beyond this are "far" (int32 and float offsets stay exact below it).
    static constexpr double kFar = double(1 << 29);
    /// Strands ahead of the next one whose vertices start() prefetches.
    static constexpr std::size_t kAhead = 4;
    /// Steps a strand may take (step counters are 32-bit, SIMD lanes).
    static constexpr int kMaxSteps = std::numeric_limits<int>::max() - 1;

    RetraceJob<TreeT>& mJob;
    const Bricks& mBricks;
    Sampler mSampler;                        ///< the general path, for any lane
    StreamlineIntegrator<Sampler> mIntegrator;
    const bool mFast, mInputMode;
    const double mStep;
    const float mThreshold2;  ///< the vanish threshold squared
    const double mMarginLength;
    Vec3d mOff{0.0}, mInv{1.0}, mScale{1.0};  ///< world to index: (p - mOff) * mInv (mFast)
    Float4 mStepScale = {0.f, 0.f, 0.f, 0.f};  ///< a step in index units per unit direction
    Group mGroups[kGroups];
    Lane mLanes[kLanes];
    int mBusy = 0;  ///< lanes tracing a strand
    std::size_t mNext = 0, mEnd = 0;
};

} // namespace lanes
} // namespace vdbhair
