#!/bin/sh
# Run one fuzz harness for a bounded time: run_fuzz.sh HARNESS SEEDS WORKDIR SECONDS [DICT]
# The corpus grows in WORKDIR/corpus (seeded from SEEDS, which stay as made); a finding is
# written to WORKDIR/ as crash-*, leak-*, timeout-*, oom-* or slow-unit-* and fails the run.
# Extra libFuzzer flags may be given in VDBHAIR_FUZZ_FLAGS (e.g. -jobs=1 -runs=10000000).
set -eu
harness=$1 seeds=$2 work=$3 seconds=$4 dict=${5:-}
mkdir -p "$work/corpus"
set -- -max_total_time="$seconds" -rss_limit_mb=2048 -malloc_limit_mb=512 -timeout=10 \
       -max_len=65536 -print_final_stats=1 -artifact_prefix="$work/"
[ -n "$dict" ] && set -- "$@" -dict="$dict"
# Third-party leaks only, each with its reason (tests/sanitizers/lsan.supp).
LSAN_OPTIONS="suppressions=$(cd "$(dirname "$0")/../sanitizers" && pwd)/lsan.supp:print_suppressions=0${LSAN_OPTIONS:+:$LSAN_OPTIONS}"
export LSAN_OPTIONS
# shellcheck disable=SC2086
exec "$harness" "$@" ${VDBHAIR_FUZZ_FLAGS:-} "$work/corpus" "$seeds"
