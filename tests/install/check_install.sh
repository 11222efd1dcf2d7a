#!/bin/sh
# Installs the build tree $1 into a temporary prefix under $2 and builds and runs a ten-line
# project against it with find_package(vdbhair) (tests/install/consumer).
set -eu
build="$1"; work="$2"; here=$(cd "$(dirname "$0")" && pwd)
rm -rf "$work"; mkdir -p "$work"
cmake --install "$build" --prefix "$work/prefix" > "$work/install.log"
test -f "$work/prefix/include/vdbhair/strands/StrandSet.h"
test -x "$work/prefix/bin/vdbhair"
ls "$work"/prefix/lib*/vdbhair/libvdbhair_image.so > /dev/null
"$work/prefix/bin/vdbhair" --version
cmake -S "$here/consumer" -B "$work/consumer" -DCMAKE_PREFIX_PATH="$work/prefix" -DCMAKE_BUILD_TYPE=Release > "$work/configure.log"
cmake --build "$work/consumer" > "$work/build.log"
"$work/consumer/consumer"
echo "ok: an installed vdbhair builds and runs a find_package(vdbhair) project"
