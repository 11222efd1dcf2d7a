#include "ChildProcess.h"

#include <vdbhair/Exceptions.h>

#include <cerrno>
#include <csignal>
#include <cstring>

#include <fcntl.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

namespace vdbhair::app {

pid_t startChild(const std::vector<std::string>& argv, const std::string& cwd, const std::string& outPath, const std::string& errPath)
{
    // Everything the child needs is prepared before fork(): between fork() and exec() it makes
    // system calls only (the parent may have other threads).
    std::vector<char*> cargv;
    for (const std::string& a : argv) cargv.push_back(const_cast<char*>(a.c_str()));
    cargv.push_back(nullptr);
    // The children's malloc asks for transparent huge pages for the memory it maps (glibc's
    // tunable glibc.malloc.hugetlb=1; a setting the batch's environment has is kept): a child
    // reads and writes whole hairstyles, where a page fault per 4 KiB is a visible share of the
    // time (docs/performance.md). A tunable is read when a process starts, so it is set here.
    std::vector<std::string> env;
    bool hasTunable = false;
    for (char** e = environ; *e; ++e) {
        std::string v = *e;
        if (v.rfind("GLIBC_TUNABLES=", 0) == 0) {
            if (v.find("glibc.malloc.hugetlb") == std::string::npos) v += (v.size() > 15 ? ":" : "") + std::string("glibc.malloc.hugetlb=1");
            hasTunable = true;
        }
        env.push_back(std::move(v));
    }
    if (!hasTunable) env.push_back("GLIBC_TUNABLES=glibc.malloc.hugetlb=1");
    std::vector<char*> cenv;
    for (const std::string& e : env) cenv.push_back(const_cast<char*>(e.c_str()));
    cenv.push_back(nullptr);
    const pid_t parent = ::getpid();
    const pid_t pid = ::fork();
    if (pid < 0) throw IoError("cannot start a process for " + argv.back() + ": " + std::strerror(errno));
    if (pid > 0) return pid;

    // The child.
    ::prctl(PR_SET_PDEATHSIG, SIGTERM);
    if (::getppid() != parent) ::_exit(143);  // the batch died before the request took hold
    const int in = ::open("/dev/null", O_RDONLY);
    const int out = ::open(outPath.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int err = ::open(errPath.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (in < 0 || out < 0 || err < 0 || ::dup2(in, 0) < 0 || ::dup2(out, 1) < 0 || ::dup2(err, 2) < 0) ::_exit(127);
    if (::chdir(cwd.c_str()) != 0) {
        static const char msg[] = "vdbhair batch: cannot enter the JOB's folder\n";
        (void)!::write(2, msg, sizeof msg - 1);
        ::_exit(127);
    }
    ::execve(cargv[0], cargv.data(), cenv.data());
    static const char msg[] = "vdbhair batch: cannot run the vdbhair program\n";
    (void)!::write(2, msg, sizeof msg - 1);
    ::_exit(127);
}

bool waitAnyChild(ChildExit& exit)
{
    int status = 0;
    rusage usage{};
    const pid_t pid = ::wait4(-1, &status, 0, &usage);
    if (pid < 0 && errno == EINTR) return false;
    if (pid <= 0) throw IoError(std::string("waiting for the batch's runs: ") + std::strerror(errno));
    exit.pid = pid;
    exit.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    exit.signal = WIFSIGNALED(status) ? WTERMSIG(status) : 0;
    exit.cpuSeconds = double(usage.ru_utime.tv_sec + usage.ru_stime.tv_sec) + 1e-6 * double(usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
    exit.peakRssKb = usage.ru_maxrss;
    return true;
}

std::string signalName(int sig)
{
    const char* abbrev = ::sigabbrev_np(sig);
    return abbrev ? std::string("SIG") + abbrev : "signal " + std::to_string(sig);
}

} // namespace vdbhair::app
