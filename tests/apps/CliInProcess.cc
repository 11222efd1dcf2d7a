// The command-line cases' in-process runner (tests/apps/cli_suite.py starts it): each request runs
// one `vdbhair` command line through vdbhair::app::run(), the entry bin/vdbhair's main() calls,
// inside this one process, with standard input from /dev/null and standard output and error in
// the files the request names, as a separate process started by cli_suite.py would have them.
// cli_suite.py makes every check itself; this program only runs the command and says its status.
//
//   vdbhair_cli_inprocess --serve
//
// Requests arrive on standard input, one JSON object a line:
//   {"argv": ["/path/to/bin/vdbhair", "info", ...], "stdout": PATH, "stderr": PATH}
// and each answer is one line on standard output: {"status": N, "clean": true|false, "why": TEXT}.
// N is what the process's exit status would be (main's return value modulo 256). "clean" is false
// when the command left state behind that a next command would see but a new process would not
// (a Ctrl-C's flag, another working folder): cli_suite.py then starts a new runner.
//
// Without --serve the program is `vdbhair` itself (its arguments go to run()), so that a command
// that starts its own executable (/proc/self/exe, as `batch` does) starts a vdbhair.
#include "Command.h"
#include "TerminalProgress.h"

#include <nlohmann/json.hpp>

#include <cstdio>
#include <cstring>
#include <iostream>
#include <string>
#include <vector>

#include <fcntl.h>
#include <unistd.h>

namespace {

/// The format flags every standard stream starts a process with; a command that changed them would
/// otherwise hand them to the next.
struct StreamState
{
    std::ios::fmtflags flags;
    std::streamsize precision;
    char fill;
};

StreamState stateOf(const std::ostream& s) { return {s.flags(), s.precision(), s.fill()}; }

void restore(std::ostream& s, const StreamState& state)
{
    s.clear();
    s.flags(state.flags);
    s.precision(state.precision);
    s.width(0);
    s.fill(state.fill);
}

/// Opens @a path for writing (created, emptied) onto file descriptor @a fd.
bool redirect(int fd, const std::string& path)
{
    const int f = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (f < 0) return false;
    const bool ok = ::dup2(f, fd) == fd;
    ::close(f);
    return ok;
}

std::string workingFolder()
{
    std::vector<char> buf(4096);
    return ::getcwd(buf.data(), buf.size()) ? std::string(buf.data()) : std::string();
}

/// Runs @a argv as bin/vdbhair would with its output in @a outPath and @a errPath; the answer line.
nlohmann::json runCommand(std::vector<std::string> argv, const std::string& outPath, const std::string& errPath,
                          int devNull, int diagnostics, const StreamState& out, const StreamState& err)
{
    const std::string folder = workingFolder();
    std::cout.flush();
    std::cerr.flush();
    std::fflush(nullptr);
    if (!redirect(STDOUT_FILENO, outPath) || !redirect(STDERR_FILENO, errPath)) {
        ::dup2(devNull, STDOUT_FILENO);
        ::dup2(diagnostics, STDERR_FILENO);
        return {{"status", nullptr}, {"clean", true}, {"why", "cannot open " + outPath + " or " + errPath + ": " + std::strerror(errno)}};
    }
    restore(std::cout, out);
    restore(std::cerr, err);
    std::cin.clear();

    std::vector<char*> args;
    for (std::string& a : argv) args.push_back(a.data());
    args.push_back(nullptr);
    // As the process's exit status: main's return value, modulo 256. An exception out of run() or a
    // crash ends this process as it would have ended the command's; cli_suite.py reads the status.
    const int status = vdbhair::app::run(int(argv.size()), args.data()) & 0xff;

    std::cout.flush();
    std::cerr.flush();
    std::fflush(nullptr);
    ::dup2(devNull, STDOUT_FILENO);
    ::dup2(diagnostics, STDERR_FILENO);

    std::string why;
    if (vdbhair::app::interruptRequested()) why = "a signal (Ctrl-C or SIGTERM) arrived during the command";
    if (workingFolder() != folder) {
        why += std::string(why.empty() ? "" : "; ") + "the command changed the working folder";
        if (::chdir(folder.c_str()) != 0) why += " (and it cannot be restored)";
    }
    return {{"status", status}, {"clean", why.empty()}, {"why", why}};
}

int serve()
{
    // The requests and answers keep the pipes cli_suite.py opened; the commands get /dev/null as
    // standard input and, between requests, as standard output.
    const int requests = ::fcntl(STDIN_FILENO, F_DUPFD_CLOEXEC, 3);
    const int answers = ::fcntl(STDOUT_FILENO, F_DUPFD_CLOEXEC, 3);
    const int diagnostics = ::fcntl(STDERR_FILENO, F_DUPFD_CLOEXEC, 3);
    const int devNull = ::open("/dev/null", O_RDWR | O_CLOEXEC);
    if (requests < 0 || answers < 0 || diagnostics < 0 || devNull < 0 || ::dup2(devNull, STDIN_FILENO) < 0 ||
        ::dup2(devNull, STDOUT_FILENO) < 0) {
        std::perror("vdbhair_cli_inprocess: cannot set up its pipes");
        return 1;
    }
    FILE* in = ::fdopen(requests, "r");
    FILE* reply = ::fdopen(answers, "w");
    if (!in || !reply) return 1;
    const StreamState out = stateOf(std::cout), err = stateOf(std::cerr);

    std::string line;
    for (int c = 0; (c = std::fgetc(in)) != EOF;) {
        if (c != '\n') {
            line.push_back(char(c));
            continue;
        }
        nlohmann::json answer;
        try {
            const nlohmann::json request = nlohmann::json::parse(line);
            answer = runCommand(request.at("argv").get<std::vector<std::string>>(), request.at("stdout").get<std::string>(),
                                request.at("stderr").get<std::string>(), devNull, diagnostics, out, err);
        } catch (const nlohmann::json::exception& e) {
            answer = {{"status", nullptr}, {"clean", true}, {"why", std::string("bad request: ") + e.what()}};
        }
        line.clear();
        const std::string text = answer.dump() + "\n";
        if (std::fwrite(text.data(), 1, text.size(), reply) != text.size() || std::fflush(reply) != 0) return 1;
    }
    return 0;
}

} // namespace

int main(int argc, char** argv)
{
    if (argc == 2 && std::strcmp(argv[1], "--serve") == 0) return serve();
    return vdbhair::app::run(argc, argv);
}
