#!/bin/sh
# Installs the build tree $1 into a temporary prefix under $2 and builds and runs a ten-line
# project against it with find_package(vdbhair) (tests/install/consumer).
set -eu
build="$1"; work="$2"; here=$(cd "$(dirname "$0")" && pwd)
rm -rf "$work"; mkdir -p "$work"
cmake --install "$build" --prefix "$work/prefix" > "$work/install.log"
test -f "$work/prefix/include/vdbhair/strands/StrandSet.h"
test -x "$work/prefix/bin/vdbhair"
test ! -e "$work/prefix/libexec/vdbhair"
ls "$work"/prefix/lib*/vdbhair/libvdbhair_image.so > /dev/null
"$work/prefix/bin/vdbhair" --version
# The installed program renders an EXR: the image module loads.
printf 'v 0 0 0\nv 0 1 0\nv 0.2 2 0\nl 1 2 3\n' > "$work/strand.obj"
"$work/prefix/bin/vdbhair" render "$work/strand.obj" -o "$work/strand.exr" --width 32 --height 32 --quiet
test -s "$work/strand.exr"
cmake -S "$here/consumer" -B "$work/consumer" -DCMAKE_PREFIX_PATH="$work/prefix" -DCMAKE_BUILD_TYPE=Release > "$work/configure.log"
cmake --build "$work/consumer" > "$work/build.log"
"$work/consumer/consumer"
# The Python module, when it was built: installed into the prefix's site-packages, it imports
# from there and works (the interpreter is the one it was built for, from the build's cache).
python=$(sed -n 's/^Python_EXECUTABLE:[A-Z]*=//p' "$build/CMakeCache.txt")
if grep -q '^VDBHAIR_PYTHON:BOOL=ON' "$build/CMakeCache.txt"; then
  module=$(find "$work/prefix" -name 'vdbhair.cpython-*.so' | head -n 1)
  test -n "$module"
  (cd "$work" && PYTHONPATH=$(dirname "$module") "$python" -c \
    "import vdbhair, numpy; s = vdbhair.Strands(numpy.zeros((2, 3)) + [[0, 0, 0], [1, 0, 0]], [0, 2]); assert len(s) == 1 and vdbhair.__file__.startswith('$work/prefix')")
  # The Blender add-on, installed with it, names that module's directory (docs/blender.md).
  grep -qx "MODULE_DIR = \"$(dirname "$module")\"" "$work/prefix/share/vdbhair/blender/vdbhair_addon/_build_info.py"
fi
echo "ok: an installed vdbhair builds and runs a find_package(vdbhair) project"
