// The `vdbhair` command: each verb lives in commands/, registered and run by Cli.cc.
#include "Command.h"

int main(int argc, char** argv) { return vdbhair::app::run(argc, argv); }
