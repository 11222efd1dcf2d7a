#include "TerminalProgress.h"

#include <vdbhair/io/FileUtil.h>

#include <algorithm>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>

#include <sys/ioctl.h>
#include <unistd.h>

namespace vdbhair::app {

namespace {

volatile std::sig_atomic_t sSignal = 0;

extern "C" void onInterrupt(int sig) { sSignal = sig; }

bool commitRefused() { return sSignal != 0; }

/// For tests of Ctrl-C that must not depend on the machine's speed: with
/// VDBHAIR_TEST_INTERRUPT_AFTER=N in the environment, the first report of N or more items done
/// raises SIGINT in the process itself, exactly as a Ctrl-C at that point would. With
/// VDBHAIR_TEST_INTERRUPT_DRAWN=1, the first line drawn with a rate and a time left does (a test
/// of the drawn bar then needs no timer that a fast machine could outrun or a slow one miss).
/// VDBHAIR_TEST_INTERRUPT_SIGNAL=TERM sends SIGTERM instead (as `timeout` and Slurm do).
/// With VDBHAIR_TEST_STOP_AT_START=VERB, a process running VERB stops itself (SIGSTOP) once its
/// handlers are installed, before its work: a test of `batch` then signals a child that is certainly
/// still running, or lets it go on (SIGCONT), in an order of its choosing.
std::uint64_t sInterruptAfter = 0;
bool sInterruptDrawn = false;
int sTestSignal = SIGINT;

/// "12", "1.2k", "3.4M": three significant digits are all a progress line needs.
std::string shortNumber(double v)
{
    char buf[32];
    if (v >= 1e9) std::snprintf(buf, sizeof buf, "%.3gG", v / 1e9);
    else if (v >= 1e6) std::snprintf(buf, sizeof buf, "%.3gM", v / 1e6);
    else if (v >= 1e4) std::snprintf(buf, sizeof buf, "%.3gk", v / 1e3);
    else std::snprintf(buf, sizeof buf, "%.0f", v);
    return buf;
}

/// "0.4 s", "42 s", "3:05", "2:10:07": short, so that a bar fits in 80 columns.
std::string duration(double seconds)
{
    seconds = std::max(0.0, seconds);
    char buf[32];
    if (seconds < 10.0) {
        std::snprintf(buf, sizeof buf, "%.1f s", seconds);
        return buf;
    }
    const long s = std::lround(seconds);
    if (s < 60) std::snprintf(buf, sizeof buf, "%ld s", s);
    else if (s < 3600) std::snprintf(buf, sizeof buf, "%ld:%02ld", s / 60, s % 60);
    else std::snprintf(buf, sizeof buf, "%ld:%02ld:%02ld", s / 3600, (s % 3600) / 60, s % 60);
    return buf;
}

int terminalColumns()
{
    winsize ws{};
    if (::ioctl(STDERR_FILENO, TIOCGWINSZ, &ws) == 0 && ws.ws_col >= 20) return ws.ws_col;
    return 80;
}

/// SIGINT and SIGTERM set sSignal, with sigaction's @a flags.
void setHandlers(int flags)
{
    struct sigaction sa{};
    sa.sa_handler = onInterrupt;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = flags;
    sigaction(SIGINT, &sa, nullptr);
    sigaction(SIGTERM, &sa, nullptr);
}

constexpr double kShowAfter = 0.25;   ///< seconds a stage runs before its line appears
constexpr double kRedrawEvery = 0.1;  ///< seconds between redraws

} // namespace

void installInterruptHandlers(const std::string& verb)
{
    // One-shot (a second Ctrl-C terminates at once); system calls restart rather than fail
    // with EINTR (a read in progress would otherwise report an I/O error, not the interruption).
    setHandlers(SA_RESETHAND | SA_RESTART);
    setCommitInterruptCheck(commitRefused);
    if (const char* n = std::getenv("VDBHAIR_TEST_INTERRUPT_AFTER"); n && *n) sInterruptAfter = std::strtoull(n, nullptr, 10);
    if (const char* d = std::getenv("VDBHAIR_TEST_INTERRUPT_DRAWN"); d && *d == '1') sInterruptDrawn = true;
    if (const char* t = std::getenv("VDBHAIR_TEST_INTERRUPT_SIGNAL"); t && std::string(t) == "TERM") sTestSignal = SIGTERM;
    if (const char* v = std::getenv("VDBHAIR_TEST_STOP_AT_START"); v && verb == v) ::raise(SIGSTOP);
}

bool interruptRequested() { return sSignal != 0; }

int interruptSignal() { return int(sSignal); }

void interruptBlockingCalls() { setHandlers(SA_RESETHAND); }  // still one-shot; no SA_RESTART

TerminalProgress::TerminalProgress(std::string verb, bool quiet)
    : mVerb(std::move(verb)), mDraw(!quiet && ::isatty(STDERR_FILENO) == 1)
{
    // A ticker redraws the line, so it moves (and the time counts) even while the library is
    // in a step that reports rarely or not at all (reading a file).
    // The ticker blocks SIGINT and SIGTERM, so that they reach the main thread and end its
    // blocking calls (batch's wait for its children).
    if (!mDraw) return;
    sigset_t block, old;
    sigemptyset(&block);
    sigaddset(&block, SIGINT);
    sigaddset(&block, SIGTERM);
    pthread_sigmask(SIG_BLOCK, &block, &old);
    mTicker = std::thread([this] {
        std::unique_lock<std::mutex> lock(mMutex);
        while (!mQuit) {
            mWake.wait_for(lock, std::chrono::duration<double>(kRedrawEvery));
            if (!mQuit && mActive) draw();
        }
    });
    pthread_sigmask(SIG_SETMASK, &old, nullptr);
}

TerminalProgress::~TerminalProgress()
{
    {
        std::lock_guard<std::mutex> lock(mMutex);
        mQuit = true;
        erase();
    }
    mWake.notify_all();
    if (mTicker.joinable()) mTicker.join();
}

void TerminalProgress::start(const char* name) { startWork(name, 0, ""); }

void TerminalProgress::startWork(const char* name, std::uint64_t total, const char* unit)
{
    std::lock_guard<std::mutex> lock(mMutex);
    erase();
    if (mActive) mOuter.push_back({mStage, mUnit, mTotal, mStart, mDone.load()});  // a stage within a stage
    mStage = name ? name : "";
    mUnit = unit ? unit : "";
    mTotal = total;
    mStart = Clock::now();
    mDone = 0;
    mActive = true;
}

void TerminalProgress::end()
{
    std::lock_guard<std::mutex> lock(mMutex);
    erase();
    mActive = !mOuter.empty();
    if (!mActive) return;
    // Back to the enclosing stage, its clock still running.
    const Saved& o = mOuter.back();
    mStage = o.stage;
    mUnit = o.unit;
    mTotal = o.total;
    mStart = o.start;
    mDone = o.done;
    mOuter.pop_back();
}

void TerminalProgress::clear()
{
    std::lock_guard<std::mutex> lock(mMutex);
    erase();
    mOuter.clear();
    mActive = false;
}

bool TerminalProgress::wasInterrupted(int percent)
{
    // A plain percentage (an OpenVDB tool): count it in hundredths of the stage.
    if (percent >= 0) return wasInterruptedAt(mTotal ? mTotal * std::uint64_t(std::min(percent, 100)) / 100 : 0, percent);
    return sSignal != 0;
}

bool TerminalProgress::wasInterruptedAt(std::uint64_t done, int)
{
    // Keep the largest: threads report out of order.
    std::uint64_t seen = mDone.load(std::memory_order_relaxed);
    while (done > seen && !mDone.compare_exchange_weak(seen, done, std::memory_order_relaxed)) {}
    if (sInterruptAfter != 0 && done >= sInterruptAfter && sSignal == 0) ::kill(::getpid(), sTestSignal);  // to the process, as a Ctrl-C: the ticker thread blocks SIGINT
    return sSignal != 0;
}

std::string TerminalProgress::formatLine(const std::string& verb, const std::string& stage, std::uint64_t done, std::uint64_t total,
                                         const std::string& unit, double elapsed, int columns)
{
    std::string tail;
    int percent = 0;
    if (total > 0) {
        done = std::min(done, total);
        percent = int(done * 100 / total);
        char pct[8];
        std::snprintf(pct, sizeof pct, "%3d%%", percent);
        tail = std::string("] ") + pct;
        if (elapsed > 0.0 && done > 0) {
            const double rate = double(done) / elapsed;
            tail += "  " + shortNumber(rate) + " " + unit + "/s";
            if (done < total) tail += "  " + duration(double(total - done) / rate) + " left";
        }
        // A steady bar: the tail's room does not change as the numbers do.
        const std::size_t fixed = 17 + unit.size() + 14;  // "] 100%  999k UNIT/s  1:23:45 left"
        if (tail.size() < fixed) tail += std::string(fixed - tail.size(), ' ');
    } else {
        tail = "  " + duration(elapsed);
    }
    std::string head = verb + ": " + stage;
    const int room = columns - 1 - int(head.size()) - int(tail.size());
    if (total == 0) {
        std::string line = head + tail;
        return line.size() < std::size_t(columns) ? line : line.substr(0, std::size_t(columns - 1));
    }
    if (room < 8) {  // no room for a bar
        std::string line = head + " " + tail.substr(2);
        while (!line.empty() && line.back() == ' ') line.pop_back();
        return line.size() < std::size_t(columns) ? line : line.substr(0, std::size_t(columns - 1));
    }
    const int width = std::min(40, room - 2);
    const int filled = width * percent / 100;
    return head + " [" + std::string(std::size_t(filled), '#') + std::string(std::size_t(width - filled), '-') + tail;
}

void TerminalProgress::draw()
{
    const double elapsed = std::chrono::duration<double>(Clock::now() - mStart).count();
    if (elapsed < kShowAfter) return;
    const std::string line = formatLine(mVerb, mStage, mDone.load(), mTotal, mUnit, elapsed, terminalColumns());
    std::fprintf(stderr, "\r%s\033[K", line.c_str());
    std::fflush(stderr);
    mShown = true;
    if (sInterruptDrawn && sSignal == 0 && mTotal > 0 && mDone.load() > 0 && mDone.load() < mTotal) ::kill(::getpid(), sTestSignal);  // to the process, as a Ctrl-C: the ticker thread blocks SIGINT
}

void TerminalProgress::erase()
{
    if (!mShown) return;
    std::fprintf(stderr, "\r\033[K");
    std::fflush(stderr);
    mShown = false;
}

} // namespace vdbhair::app
