#!/bin/sh
# The light program (apps/lite/Lite.cc) against the full one: the same output, errors and exit
# status for every command line it serves or hands on, and no OpenVDB library loaded.
#   lite_test.sh LAUNCHER FIXTURES WORK [DATA]
# LAUNCHER is bin/vdbhair; the two programs are in ../libexec/vdbhair/ from it. DATA, when it is a
# folder (the shared real hairstyles), adds their files to those summarized by both.
set -u
launcher="$1"; fx="$2"; work="$3"; data="${4:-}"
dir=$(dirname "$launcher")/../libexec/vdbhair
full="$dir/vdbhair"; lite="$dir/vdbhair-lite"
fail() { echo "FAIL: $*"; exit 1; }
rm -rf "$work"; mkdir -p "$work"
[ -x "$lite" ] || fail "no light program at $lite"

# No OpenVDB library, directly or through another library; and none loaded for --help.
ldd "$lite" | grep -q openvdb && fail "the light program links OpenVDB: $(ldd "$lite" | grep openvdb)"
LD_DEBUG=libs "$launcher" --help 2>"$work/ld.txt" >/dev/null || fail "--help: exit $?"
grep -q "calling init: .*libtbb" "$work/ld.txt" || fail "LD_DEBUG=libs shows no library loading (cannot check): $(head -3 "$work/ld.txt")"
grep -q "openvdb" "$work/ld.txt" && fail "vdbhair --help loaded OpenVDB: $(grep -m1 openvdb "$work/ld.txt")"

# same NAME ARGS...: the light and the full program print the same and exit with the same status.
n=0
same() {
    name="$1"; shift
    n=$((n + 1))
    "$full" "$@" >"$work/full.out" 2>"$work/full.err"; fs=$?
    "$lite" "$@" >"$work/lite.out" 2>"$work/lite.err"; ls=$?
    [ $fs -eq $ls ] || fail "$name: exit $ls, the full program's $fs ($(head -c 300 "$work/lite.err"))"
    cmp -s "$work/full.out" "$work/lite.out" || fail "$name: stdout differs: $(diff "$work/full.out" "$work/lite.out" | head -5)"
    cmp -s "$work/full.err" "$work/lite.err" || fail "$name: stderr differs: $(diff "$work/full.err" "$work/lite.err" | head -5)"
}
same "--help" --help
same "-h" -h
same "--version" --version
same "no verb" 
same "help" help
same "help info" help info
same "info --help" info --help
same "an unknown verb" inf x.hair
same "an unknown option" --bogus
same "info: an unknown option" info --bogus x.hair
same "info: no file" info
same "info: a missing file" info "$work/missing.data"
same "info: an unknown extension" info "$fx/good.hair.txt"
same "info: a folder" info "$work"
for f in "$fx"/*.hair "$fx"/*.data "$fx"/*.ply "$fx"/*.obj "$fx"/*.usda "$fx"/*.tfx "$fx"/*.bin "$fx"/*.convdata; do
    [ -f "$f" ] || continue
    same "info $f" info "$f"
    same "info $f --json" info "$f" --json
    same "info $f --strict --quiet" info "$f" --strict --quiet
done
# What it hands on: the verbs it does not serve, their help, and .vdb files.
for f in "$fx"/*.vdb; do
    [ -f "$f" ] || continue
    same "info $f" info "$f" --json
    same "info $f --grid strands" info "$f" --grid strands
    break
done
same "field --help" field --help
same "help field" help field
same "convert: bad input" convert "$work/missing.hair" "$work/x.hair"
if [ -n "$data" ] && [ -d "$data" ]; then
    for f in "$data"/cyhair/*.hair "$data"/usc_data/*.data "$data"/ply/*.ply "$data"/ct2hair_bin/*.bin \
             "$data"/hairnet_convdata/*.convdata "$data"/tressfx/*/*.tfx; do
        [ -f "$f" ] || continue
        same "info $f --json" info "$f" --json
    done
else
    echo "note: no shared data folder ($data): real hairstyles not summarized"
fi
# Through the launcher: --help and info come from the light program, the same text.
"$launcher" --help >"$work/l.out" || fail "launcher --help: exit $?"
"$full" --help >"$work/f.out"
cmp -s "$work/l.out" "$work/f.out" || fail "launcher --help differs from the full program's"
echo "ok: the light program matches the full one on $n command lines and loads no OpenVDB"
