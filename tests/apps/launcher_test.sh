#!/bin/sh
# The launcher bin/vdbhair (apps/launcher/Launcher.cc), against stand-in programs that print their
# name, arguments and GLIBC_TUNABLES: it starts ../libexec/vdbhair/vdbhair with the same arguments
# and glibc.malloc.hugetlb=1 added to the tunables, or vdbhair-lite next to it for a command line
# that starts with info, help or an option or has no word; it keeps a hugetlb setting the
# environment has, and names the program it cannot start.
set -u
launcher="$1"; work="$2"
fail() { echo "FAIL: $*"; exit 1; }
rm -rf "$work"; mkdir -p "$work/bin" "$work/libexec/vdbhair"
cp "$launcher" "$work/bin/vdbhair"
for p in vdbhair vdbhair-lite; do
    printf '#!/bin/sh\necho "%s args: $*"\necho "tunables: $GLIBC_TUNABLES"\n' "$p" > "$work/libexec/vdbhair/$p"
    chmod +x "$work/libexec/vdbhair/$p"
done
out=$(env -u GLIBC_TUNABLES "$work/bin/vdbhair" field "a b.hair" -o x.vdb) || fail "exit $?: $out"
[ "$out" = "$(printf 'vdbhair args: field a b.hair -o x.vdb\ntunables: glibc.malloc.hugetlb=1')" ] || fail "unset: $out"
out=$(GLIBC_TUNABLES=glibc.malloc.arena_max=2 "$work/bin/vdbhair" info) || fail "exit $?: $out"
[ "$out" = "$(printf 'vdbhair-lite args: info\ntunables: glibc.malloc.arena_max=2:glibc.malloc.hugetlb=1')" ] || fail "appended: $out"
out=$(GLIBC_TUNABLES=glibc.malloc.hugetlb=0 "$work/bin/vdbhair" convert) || fail "exit $?: $out"
[ "$out" = "$(printf 'vdbhair args: convert\ntunables: glibc.malloc.hugetlb=0')" ] || fail "kept: $out"
# Which program: the light one for info, help, an option first or nothing; the full one otherwise.
for args in "" "--help" "-h" "help" "help field" "info x.vdb" "--bogus field"; do
    out=$("$work/bin/vdbhair" $args | head -1)
    [ "$out" = "vdbhair-lite args: $args" ] || fail "'$args' should start the light program: $out"
done
for args in "field --help" "inf x" "information" "refine a.hair"; do
    out=$("$work/bin/vdbhair" $args | head -1)
    [ "$out" = "vdbhair args: $args" ] || fail "'$args' should start the full program: $out"
done
# Through a symbolic link (a user's ~/bin/vdbhair): the launcher's own folder, not the link's.
mkdir -p "$work/elsewhere"; ln -s "$work/bin/vdbhair" "$work/elsewhere/vdbhair"
out=$("$work/elsewhere/vdbhair" --version) || fail "through a link: exit $?: $out"
rm "$work/libexec/vdbhair/vdbhair"
out=$("$work/bin/vdbhair" field 2>&1); status=$?
[ $status -eq 127 ] || fail "a missing program: exit $status"
echo "$out" | grep -q "^vdbhair: cannot start .*libexec/vdbhair/vdbhair: No such file or directory$" || fail "a missing program: $out"
rm "$work/libexec/vdbhair/vdbhair-lite"
out=$("$work/bin/vdbhair" info 2>&1); status=$?
[ $status -eq 127 ] || fail "a missing light program: exit $status"
echo "$out" | grep -q "^vdbhair: cannot start .*libexec/vdbhair/vdbhair-lite: No such file or directory$" || fail "a missing light program: $out"
echo "ok: the launcher starts the program with glibc.malloc.hugetlb=1, the light one for info, help and options, keeps a setting, follows links, names a missing program"
