// The light `vdbhair` program: the verbs' list and help, and `info` of a strand file, without the
// OpenVDB library. Binding Debian's libopenvdb.so (62,000 relocations) takes about 50 ms at every
// start of a program that links it, against a millisecond or two here: `vdbhair --help` and
// `vdbhair info hair.data` need none of it. The launcher (launcher/Launcher.cc) starts this program
// for a command line whose first word is `info`, `help` or an option, or that has none; whatever
// this program does not serve (another verb, its help, `info` of a .vdb file) it hands, with the
// same command line, to the full program next to it, which parses it again from the start.
//
// Both programs parse with the same code (Cli.cc's runVerbs(), the verbs' table, Info.cc's
// registration), so their help, errors and exit codes are the same; tests/apps/lite_test.sh
// compares them.
#include "../Command.h"
#include "../commands/Info.h"

#include <cerrno>
#include <climits>
#include <cstdio>
#include <cstring>
#include <string>

#include <unistd.h>

#ifndef VDBHAIR_FULL_PROGRAM_NAME
#error "VDBHAIR_FULL_PROGRAM_NAME: the full program's file name, in this program's folder"
#endif

namespace {

char** sArgv = nullptr;

/// Replace this process by the full program with the same command line and environment.
[[noreturn]] void execFullProgram()
{
    char self[PATH_MAX];
    const ssize_t n = ::readlink("/proc/self/exe", self, sizeof(self) - 1);
    std::string program = n > 0 ? std::string(self, std::size_t(n)) : std::string();
    program.erase(program.rfind('/') + 1);
    program += VDBHAIR_FULL_PROGRAM_NAME;
    std::fflush(nullptr);
    ::execv(program.c_str(), sArgv);
    std::fprintf(stderr, "vdbhair: cannot start %s: %s\n", program.c_str(), std::strerror(errno));
    std::_Exit(127);
}

/// The verbs as the full program lists them; only `info` is served here, and of it only strand files.
std::vector<vdbhair::app::Command> addLiteCommands(CLI::App& app, vdbhair::app::CommonOptions& common)
{
    using namespace vdbhair::app;
    std::vector<Command> commands;
    for (const Verb& v : verbs()) {
        if (std::strcmp(v.name, "info") == 0) {
            commands.push_back(addInfoVerb(app, common, [](const InfoParams&, const CommonOptions&) -> int { execFullProgram(); }));
        } else {
            commands.push_back({addVerb(app, v.name), [] () -> int { execFullProgram(); }});
        }
    }
    return commands;
}

} // namespace

int main(int argc, char** argv)
{
    sArgv = argv;
    // A verb other than info, or its help (`vdbhair help VERB`), is the full program's from the start:
    // the subcommands registered above carry no options.
    const char* word = argc >= 2 && std::strcmp(argv[1], "help") == 0 ? (argc >= 3 ? argv[2] : nullptr) : (argc >= 2 ? argv[1] : nullptr);
    if (word && word[0] != '-' && std::strcmp(word, "info") != 0) {
        for (const vdbhair::app::Verb& v : vdbhair::app::verbs()) {
            if (std::strcmp(word, v.name) == 0) execFullProgram();
        }
    }
    return vdbhair::app::runVerbs(argc, argv, addLiteCommands);
}
