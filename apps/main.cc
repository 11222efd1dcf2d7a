// The `vdbhair` command: a thin main; each verb lives in commands/.
#include "Command.h"

int main(int argc, char** argv) { return vdbhair::app::run(argc, argv); }
