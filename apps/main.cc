// The `vdbhair` command: a thin main; each verb lives in commands/.
#include "Command.h"

#include <cstdio>
#include <cstdlib>
#include <iostream>

int main(int argc, char** argv)
{
    const int code = vdbhair::app::run(argc, argv);
    // Not a return from main: what the verb kept (keepUntilExit()) goes with the process instead of
    // being freed piece by piece. vdbhair registers nothing to run at exit (and liblog4cplus's
    // finalizer only waits for its threads); what exit would still do for it is flush the streams.
    std::cout.flush();
    std::cerr.flush();
    std::fflush(nullptr);
    std::_Exit(code);
}
