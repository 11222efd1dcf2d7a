#!/usr/bin/env bash
# Runs one command-line test: a command, its expected exit status and output, and what it must
# (not) leave on disk.
#   cli_test.sh [--exit N|nonzero] [--stdout RE]... [--no-stdout RE]... [--stderr RE]... [--stderr-lines N]
#               [--absent PATH] [--exists PATH] [--keep PATH] -- COMMAND [ARGS...]
# --keep PATH: the file must exist before and be byte-identical after the command.
set -u
want_exit=0; out_re=(); no_out_re=(); err_re=(); err_lines=""; absent=(); exists=(); keep=()
while [ $# -gt 0 ]; do
  case "$1" in
    --exit) want_exit="$2"; shift 2 ;;
    --stdout) out_re+=("$2"); shift 2 ;;
    --no-stdout) no_out_re+=("$2"); shift 2 ;;
    --stderr) err_re+=("$2"); shift 2 ;;
    --stderr-lines) err_lines="$2"; shift 2 ;;
    --absent) absent+=("$2"); shift 2 ;;
    --exists) exists+=("$2"); shift 2 ;;
    --keep) keep+=("$2"); shift 2 ;;
    --) shift; break ;;
    *) echo "cli_test.sh: unknown option $1" >&2; exit 2 ;;
  esac
done
fail() { echo "FAIL: $*" >&2; echo "--- stdout:" >&2; cat "$tmp/out" >&2; echo "--- stderr:" >&2; cat "$tmp/err" >&2; exit 1; }
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
for f in ${keep[@]+"${keep[@]}"}; do
  [ -f "$f" ] || { echo "FAIL: --keep $f does not exist before the run" >&2; exit 1; }
  sha256sum "$f" > "$tmp/keep.$(echo "$f" | md5sum | cut -c1-8)"
done
for f in ${absent[@]+"${absent[@]}"}; do rm -rf "$f"; done
"$@" > "$tmp/out" 2> "$tmp/err"
status=$?
echo "\$ $*  (exit $status)"
if [ "$want_exit" = nonzero ]; then
  [ $status -ne 0 ] || fail "expected a non-zero exit status, got 0"
else
  [ $status -eq "$want_exit" ] || fail "expected exit status $want_exit, got $status"
fi
for re in ${out_re[@]+"${out_re[@]}"}; do grep -E -q -- "$re" "$tmp/out" || fail "stdout does not match /$re/"; done
for re in ${no_out_re[@]+"${no_out_re[@]}"}; do ! grep -E -q -- "$re" "$tmp/out" || fail "stdout must not match /$re/"; done
for re in ${err_re[@]+"${err_re[@]}"}; do grep -E -q -- "$re" "$tmp/err" || fail "stderr does not match /$re/"; done
if [ -n "$err_lines" ]; then
  n=$(wc -l < "$tmp/err"); [ "$n" -eq "$err_lines" ] || fail "expected $err_lines line(s) on stderr, got $n"
fi
for f in ${absent[@]+"${absent[@]}"}; do [ ! -e "$f" ] || fail "$f must not exist after the run"; done
for f in ${exists[@]+"${exists[@]}"}; do [ -e "$f" ] || fail "$f was not written"; done
for f in ${keep[@]+"${keep[@]}"}; do
  sha256sum -c --quiet "$tmp/keep.$(echo "$f" | md5sum | cut -c1-8)" >/dev/null 2>&1 || fail "$f was modified"
done
# No temporary output may be left behind for any file named in the checks.
for f in ${absent[@]+"${absent[@]}"} ${exists[@]+"${exists[@]}"} ${keep[@]+"${keep[@]}"}; do
  # Only this file's own temporaries (".STEM.vdbhair-tmp-*"): other tests write next to it in parallel.
  d=$(dirname "$f"); b=$(basename "$f"); stem=${b%.*}
  if ls -a "$d" 2>/dev/null | grep -qF ".$stem.vdbhair-tmp-"; then fail "a temporary file of $f was left in $d"; fi
done
exit 0
