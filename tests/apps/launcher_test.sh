#!/bin/sh
# The launcher bin/vdbhair (apps/launcher/Launcher.cc), against a stand-in program that prints its
# arguments and GLIBC_TUNABLES: it starts ../libexec/vdbhair/vdbhair with the same arguments and
# glibc.malloc.hugetlb=1 added to the tunables, keeps a hugetlb setting the environment has, and
# names the program it cannot start.
set -u
launcher="$1"; work="$2"
fail() { echo "FAIL: $*"; exit 1; }
rm -rf "$work"; mkdir -p "$work/bin" "$work/libexec/vdbhair"
cp "$launcher" "$work/bin/vdbhair"
printf '#!/bin/sh\necho "args: $*"\necho "tunables: $GLIBC_TUNABLES"\n' > "$work/libexec/vdbhair/vdbhair"
chmod +x "$work/libexec/vdbhair/vdbhair"
out=$(env -u GLIBC_TUNABLES "$work/bin/vdbhair" field "a b.hair" -o x.vdb) || fail "exit $?: $out"
[ "$out" = "$(printf 'args: field a b.hair -o x.vdb\ntunables: glibc.malloc.hugetlb=1')" ] || fail "unset: $out"
out=$(GLIBC_TUNABLES=glibc.malloc.arena_max=2 "$work/bin/vdbhair" info) || fail "exit $?: $out"
[ "$out" = "$(printf 'args: info\ntunables: glibc.malloc.arena_max=2:glibc.malloc.hugetlb=1')" ] || fail "appended: $out"
out=$(GLIBC_TUNABLES=glibc.malloc.hugetlb=0 "$work/bin/vdbhair" info) || fail "exit $?: $out"
[ "$out" = "$(printf 'args: info\ntunables: glibc.malloc.hugetlb=0')" ] || fail "kept: $out"
# Through a symbolic link (a user's ~/bin/vdbhair): the launcher's own folder, not the link's.
mkdir -p "$work/elsewhere"; ln -s "$work/bin/vdbhair" "$work/elsewhere/vdbhair"
out=$("$work/elsewhere/vdbhair" --version) || fail "through a link: exit $?: $out"
rm "$work/libexec/vdbhair/vdbhair"
out=$("$work/bin/vdbhair" info 2>&1); status=$?
[ $status -eq 127 ] || fail "a missing program: exit $status"
echo "$out" | grep -q "^vdbhair: cannot start .*libexec/vdbhair/vdbhair: No such file or directory$" || fail "a missing program: $out"
echo "ok: the launcher starts the program with glibc.malloc.hugetlb=1, keeps a setting, follows links, names a missing program"
