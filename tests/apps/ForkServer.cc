// vdbhair_forkserver: runs `vdbhair` command lines for the test runners (cli_suite.py,
// bad_inputs.py) in processes forked from this one, instead of starting the program anew.
//
// Why: every process that links OpenVDB spends about 60 ms, most of its start, in the dynamic
// loader binding Debian's libopenvdb (built with -z now: 69,000 relocations); the suite starts
// the command about 500 times. This program links the same code as `vdbhair` (the
// vdbhair_commands library and vdbhair::app::run, which is all of `vdbhair`'s main) and loads it
// once; each command line then runs in a child forked from it, in a fresh process whose state at
// app::run is that of a new `vdbhair` at main (this program does nothing else before it forks: no
// output, no library call beyond loading), with its own standard streams, folder and exit status.
// Two differences: the child has only the one thread (the four idle threads liblog4cplus starts
// at load are not copied; nothing in vdbhair uses them), and it ends by _Exit after flushing its
// streams (below). What it does not exercise is the loading itself and the exit handlers: the runners exec the real binary
// for every case that needs its own executable (batch starts /proc/self/exe), for the fixtures
// and the shell-driven tests, and for everything when VDBHAIR_CLI_EXEC=1.
//
// Protocol, on standard input and output, one request and one reply a line:
//   request  NUL-separated fields, ending in a newline:  CWD \0 STDOUT \0 STDERR \0 ARG0 \0 ARG1 ... \n
//            (arguments with a newline are not supported: the runners exec those)
//   reply    "pid P" once the child runs, then "exit N" or "signal N" when it ends (a runner with a
//            time limit kills P)
#include "Command.h"

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <string>
#include <vector>

namespace {

bool readRequest(std::vector<std::string>& fields)
{
    std::string line;
    if (!std::getline(std::cin, line)) return false;
    fields.clear();
    std::size_t at = 0;
    while (true) {
        const std::size_t end = line.find('\0', at);
        fields.push_back(line.substr(at, end == std::string::npos ? std::string::npos : end - at));
        if (end == std::string::npos) break;
        at = end + 1;
    }
    return true;
}

[[noreturn]] void fail(const char* what)
{
    std::perror(what);
    std::_Exit(127);
}

/// The child: standard streams and folder of the request, then vdbhair's main.
[[noreturn]] void runChild(const std::vector<std::string>& f)
{
    const int in = ::open("/dev/null", O_RDONLY);
    const int out = ::open(f[1].c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int err = ::open(f[2].c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (in < 0 || out < 0 || err < 0) fail("vdbhair_forkserver: open");
    if (::dup2(in, 0) < 0 || ::dup2(out, 1) < 0 || ::dup2(err, 2) < 0) fail("vdbhair_forkserver: dup2");
    ::close(in);
    ::close(out);
    ::close(err);
    if (::chdir(f[0].c_str()) != 0) fail("vdbhair_forkserver: chdir");
    std::vector<char*> argv;
    for (std::size_t i = 3; i < f.size(); ++i) argv.push_back(const_cast<char*>(f[i].c_str()));
    argv.push_back(nullptr);
    const int code = vdbhair::app::run(int(argv.size() - 1), argv.data());
    // Not exit(): liblog4cplus (OpenVDB's logging) starts a pool of threads when it is loaded, and
    // its finalizer at exit waits for them, which a forked child does not have (fork copies only
    // the calling thread). vdbhair registers nothing to run at exit; what exit would still do for
    // it is flush the streams.
    std::cout.flush();
    std::cerr.flush();
    std::fflush(nullptr);
    std::_Exit(code);
}

} // namespace

int main()
{
    std::vector<std::string> fields;
    while (readRequest(fields)) {
        if (fields.size() < 4) {
            std::printf("error malformed request\n");
            std::fflush(stdout);
            continue;
        }
        std::fflush(stdout);  // nothing buffered may reach the child's streams
        const pid_t pid = ::fork();
        if (pid < 0) fail("vdbhair_forkserver: fork");
        if (pid == 0) runChild(fields);
        std::printf("pid %d\n", int(pid));
        std::fflush(stdout);
        int status = 0;
        while (::waitpid(pid, &status, 0) < 0) {
            if (errno != EINTR) fail("vdbhair_forkserver: waitpid");
        }
        if (WIFSIGNALED(status)) std::printf("signal %d\n", WTERMSIG(status));
        else std::printf("exit %d\n", WEXITSTATUS(status));
        std::fflush(stdout);
    }
    return 0;
}
