#!/usr/bin/env bash
# The README's test command: install, build, and run every test (unit and command-line); then the
# unit tests again under AddressSanitizer and UndefinedBehaviorSanitizer, built in ./build-asan
# (only the test program and the library it links; skipped with VDBHAIR_SKIP_SANITIZERS=1).
# Arguments go to both ctest runs (e.g. -R TestRefine).
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/setup.sh --tests
./scripts/build.sh -DVDBHAIR_CHECK_HEADERS=ON
(cd build && ctest --output-on-failure -j 2 "$@")
if [ "${VDBHAIR_SKIP_SANITIZERS:-0}" = 1 ]; then
  echo "test.sh: VDBHAIR_SKIP_SANITIZERS=1: the sanitizer run is skipped"
  exit 0
fi
# -O0 -g1: the quickest compile (CI builds this folder from scratch when its ccache is cold), with
# line numbers in the stacks. The first report of either sanitizer, or a leak, fails its test
# (tests/CMakeLists.txt sets ASAN_OPTIONS, UBSAN_OPTIONS and LSAN_OPTIONS).
cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=RelWithDebInfo "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O0 -g1 -DNDEBUG" \
      -DVDBHAIR_SANITIZE=ON -DVDBHAIR_PYTHON=OFF -DVDBHAIR_BUILD_BENCHMARKS=OFF >/dev/null
cmake --build build-asan -j 2 --target vdbhair_tests
(cd build-asan && ctest --output-on-failure -j 2 -L unit "$@")
