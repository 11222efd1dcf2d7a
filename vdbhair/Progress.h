/// @file Progress.h
/// @brief Progress and interruption for long work, in OpenVDB's interrupter pattern
/// (`openvdb/util/NullInterrupter.h`): library functions take an optional
/// `openvdb::util::NullInterrupter*`, call start(name) and end() around a stage and
/// wasInterrupted(percent) as work completes, and throw InterruptedError when it says stop.
///
/// WorkInterrupter adds the size of a stage (its count and unit), so that a display can show a
/// rate ("strands/s") and the time left; any plain NullInterrupter still works. ProgressCounter
/// is what the library's loops use: items completed on any thread are counted and reported.
///
/// Interruption never changes results: it only stops work, and a stopped function throws.
#pragma once

#include <openvdb/util/NullInterrupter.h>

#include <algorithm>
#include <atomic>
#include <cstdint>

namespace vdbhair {

/// @brief An interrupter that is also told how much work a stage holds.
class WorkInterrupter : public openvdb::util::NullInterrupter
{
public:
    /// @brief Start a stage of @a total items of @a unit ("strands", "segments"). The default
    /// calls start(name).
    virtual void startWork(const char* name, std::uint64_t total, const char* unit)
    {
        (void)total;
        (void)unit;
        start(name);
    }
    /// @brief @a done of the stage's total items are complete (exact, where the percentage is
    /// coarse); the default calls wasInterrupted(percent).
    /// @return true if the work should stop.
    virtual bool wasInterruptedAt(std::uint64_t done, int percent) { (void)done; return wasInterrupted(percent); }
};

/// @brief Counts completed items of one stage from any number of threads and reports the
/// percentage to an interrupter (which may be null: then the counter does nothing).
///
/// The constructor starts the stage (WorkInterrupter::startWork when the interrupter is one,
/// otherwise NullInterrupter::start), finish() or the destructor ends it.
/// @warning add() and interrupted() are thread-safe; the interrupter's wasInterrupted() is
/// called from whichever thread adds, so it must be thread-safe too.
class ProgressCounter
{
public:
    ProgressCounter(openvdb::util::NullInterrupter* interrupter, const char* name, std::uint64_t total,
                    const char* unit)
        : mInterrupter(interrupter), mTotal(total)
    {
        if (!mInterrupter) return;
        mWork = dynamic_cast<WorkInterrupter*>(mInterrupter);
        if (mWork) mWork->startWork(name, total, unit);
        else mInterrupter->start(name);
    }
    ~ProgressCounter() { finish(); }
    /// @brief End the stage now (before the next one starts); the destructor then does nothing.
    void finish()
    {
        if (mInterrupter && !mFinished) mInterrupter->end();
        mFinished = true;
    }
    ProgressCounter(const ProgressCounter&) = delete;
    ProgressCounter& operator=(const ProgressCounter&) = delete;

    /// @brief Count @a n more completed items.
    /// @return true if the work should stop.
    bool add(std::uint64_t n)
    {
        if (!mInterrupter) return false;
        const std::uint64_t done = mDone.fetch_add(n, std::memory_order_relaxed) + n;
        const int percent = mTotal ? int(std::min<std::uint64_t>(done, mTotal) * 100 / mTotal) : 100;
        if (mWork ? mWork->wasInterruptedAt(done, percent) : mInterrupter->wasInterrupted(percent)) {
            mStop.store(true, std::memory_order_relaxed);
        }
        return mStop.load(std::memory_order_relaxed);
    }
    /// @brief Whether the work should stop (asks the interrupter).
    bool interrupted()
    {
        if (!mInterrupter) return false;
        if (mInterrupter->wasInterrupted()) mStop.store(true, std::memory_order_relaxed);
        return mStop.load(std::memory_order_relaxed);
    }
    /// @brief Whether any call so far said stop (does not ask again).
    bool stopped() const { return mStop.load(std::memory_order_relaxed); }
    bool active() const { return mInterrupter != nullptr; }

private:
    openvdb::util::NullInterrupter* mInterrupter;
    WorkInterrupter* mWork = nullptr;
    std::uint64_t mTotal;
    std::atomic<std::uint64_t> mDone{0};
    std::atomic<bool> mStop{false};
    bool mFinished = false;
};

} // namespace vdbhair
