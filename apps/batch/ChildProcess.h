/// @file ChildProcess.h
/// @brief Running one input of a batch as a process of its own: a crash, an abort or the kernel's
/// OOM killer ends that process only, and wait4()'s resource usage gives its peak memory and CPU
/// time. The batch runs several at once and reaps whichever ends first.
#pragma once

#include <string>
#include <vector>

#include <sys/types.h>

namespace vdbhair::app {

/// @brief Start @a argv (argv[0] the program's path) in the folder @a cwd with standard input
/// from /dev/null and standard output and error into the files @a outPath and @a errPath
/// (created or truncated). The child asks the kernel for SIGTERM when the batch dies
/// (PR_SET_PDEATHSIG), so a killed batch leaves no run going on without its record.
/// @return its process id.
/// @throw IoError if the process cannot be created (the exec's own failure shows as exit status 127
/// and a line in @a errPath).
pid_t startChild(const std::vector<std::string>& argv, const std::string& cwd, const std::string& outPath, const std::string& errPath);

/// How a child ended, as wait4() reports it.
struct ChildExit
{
    pid_t pid = -1;
    int exitCode = -1;       ///< its exit status, or -1 when a signal ended it
    int signal = 0;          ///< the signal that ended it, or 0
    double cpuSeconds = 0.0; ///< user + system time
    long peakRssKb = 0;      ///< ru_maxrss: its largest resident set, in KiB
};

/// @brief Wait for any child to end.
/// @return false (and @a exit untouched) when a signal interrupted the wait.
/// @throw IoError when there is no child to wait for.
bool waitAnyChild(ChildExit& exit);

/// @brief The name of signal @a sig ("SIGKILL"), or "signal N".
std::string signalName(int sig);

} // namespace vdbhair::app
