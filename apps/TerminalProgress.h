/// @file TerminalProgress.h
/// @brief The command's progress bar and Ctrl-C handling.
///
/// TerminalProgress is the interrupter (vdbhair/Progress.h, OpenVDB's pattern) every long command
/// hands to the library. On a terminal it draws one line on stderr —
/// `fit: fitting p-helicoids [#######-----]  58%  1.2k strands/s  3.0 s left` —
/// redrawn ten times a second by a ticker thread (so it moves even through steps that report
/// rarely), shown only once a stage has run for a quarter of a second and erased when it ends;
/// it draws nothing when stderr is not a terminal or with --quiet.
///
/// Ctrl-C (SIGINT) and SIGTERM set a flag the library polls through wasInterrupted(): work stops
/// at the next check, the library throws InterruptedError, temporaries are removed and the
/// command exits with status 130 and nothing written. The handler is one-shot: a second Ctrl-C
/// terminates at once (the operating system's default).
#pragma once

#include <vdbhair/Progress.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace vdbhair::app {

/// @brief Install the SIGINT/SIGTERM handlers and make AtomicOutput::commit() refuse to rename
/// once a signal has arrived. @a verb is the verb about to run (for the test hooks, see the .cc).
void installInterruptHandlers(const std::string& verb);

/// @brief Whether Ctrl-C (or SIGTERM) has arrived.
bool interruptRequested();

/// @brief The signal that interrupted the command (SIGINT or SIGTERM), or 0.
int interruptSignal();

/// @brief Let Ctrl-C and SIGTERM end a blocking system call with EINTR instead of restarting it
/// (`batch` waits for its children in wait4() and must wake to pass the signal on). Call after
/// installInterruptHandlers().
void interruptBlockingCalls();

class TerminalProgress : public WorkInterrupter
{
public:
    /// @param verb the command's name, in front of the line
    /// @param quiet no drawing at all (Ctrl-C still works)
    TerminalProgress(std::string verb, bool quiet);
    ~TerminalProgress() override;

    void start(const char* name = nullptr) override;
    void startWork(const char* name, std::uint64_t total, const char* unit) override;
    /// Ends the current stage; a stage started within another returns to that one.
    void end() override;
    /// Ends every stage and erases the line (before an error message).
    void clear();
    /// Thread-safe and cheap: records the percentage, reports Ctrl-C.
    bool wasInterrupted(int percent = -1) override;
    bool wasInterruptedAt(std::uint64_t done, int percent) override;

    /// Whether this object draws (stderr is a terminal and not --quiet).
    bool drawing() const { return mDraw; }

    /// @brief The line drawn for a stage (exposed for tests): name, bar, percent, rate, time left.
    /// @param done items complete of @a total; total 0 for work of unknown size (then: elapsed time only)
    static std::string formatLine(const std::string& verb, const std::string& stage, std::uint64_t done, std::uint64_t total,
                                  const std::string& unit, double elapsedSeconds, int columns);

private:
    using Clock = std::chrono::steady_clock;
    void draw();   ///< with mMutex held
    void erase();  ///< with mMutex held

    std::string mVerb;
    bool mDraw = false;
    std::mutex mMutex;                 ///< guards the fields below and the terminal
    std::string mStage, mUnit;
    std::uint64_t mTotal = 0;
    Clock::time_point mStart;
    bool mShown = false;               ///< a line is on the terminal
    bool mQuit = false;
    std::atomic<std::uint64_t> mDone{0};
    struct Saved
    {
        std::string stage, unit;
        std::uint64_t total;
        Clock::time_point start;
        std::uint64_t done;
    };
    std::vector<Saved> mOuter;         ///< the stages this one runs within, innermost last
    std::atomic<bool> mActive{false};
    std::condition_variable mWake;
    std::thread mTicker;               ///< redraws every 0.1 s while drawing()
};

} // namespace vdbhair::app
