#!/usr/bin/env bash
# `vdbhair batch` for real: a generated dataset, runs killed halfway and resumed, a corrupt input,
# shards and their merge, and a one-node Slurm cluster when Debian's slurm-wlm is installed.
#   batch_test.sh CLI SOURCE_DIR WORK_DIR CASE
# CASE: resume-term | resume-kill | corrupt | crash | out-of-memory | more-outputs | shard | slurm
# Each case works in WORK_DIR/CASE (removed first) and prints "ok: ..." when it passes.
set -u
cli=$1; src=$2; work=$3/$4; case=$4
fail() { echo "FAIL: $*" >&2; exit 1; }
rm -rf "$work"; mkdir -p "$work/data"
cd "$work" || exit 1

# The dataset: N copies of the bundled ponytail at 8 vertices a strand (one convert, then copies:
# a process start is most of a small run's time). Each output names its input in its metadata.
make_data() {
  local n=$1 i
  "$cli" convert "$src/scenes/default/ponytail.hair" data/style00.hair --resample 8 --quiet || fail "convert"
  for i in $(seq 1 $((n - 1))); do cp data/style00.hair "data/style$(printf %02d "$i").hair"; done
}
# JOB: field over data/*.hair, outputs {stem}.vdb.
write_job() {
  cat > job.json <<JSON
{"inputs": "data/*.hair", "verb": "field", "args": ["--voxel-size", "2"], "output": "{stem}.vdb"}
JSON
}
# Outputs of two folders equal, .vdb compared after the header's random file UUID (bytes 22-57).
same_outputs() {
  local a=$1 b=$2 f n=0
  for f in "$a"/*.vdb; do
    cmp -s -i 57 "$f" "$b/$(basename "$f")" || fail "$(basename "$f") differs between $a and $b"
    n=$((n + 1))
  done
  [ "$(ls "$b"/*.vdb | wc -l)" -eq "$n" ] || fail "$b holds other outputs than $a"
  echo "$n"
}
# Records of each input (the latest per input): "input output status" lines, sorted.
record_set() {
  /usr/bin/python3 - "$1" <<'PY'
import json, sys
latest = {}
for line in open(sys.argv[1]):
    try:
        r = json.loads(line)
    except ValueError:
        continue
    latest[r["input"]] = (r["output"], r["status"])
for k in sorted(latest):
    print(k, *latest[k])
PY
}
lines() { if [ -f "$1" ]; then grep -c . "$1"; else echo 0; fi; }
# Waits are for events, polled every 10 ms (with bash's own read and /proc, so that a poll starts no
# process), with a generous bound (20 s) that only a hang reaches.
mkfifo .tick && exec 7<> .tick  # never written: a read of it with -t is a sleep
tick() { read -r -t 0.01 -u 7 _; }
#   wait_for WHAT COMMAND...   # until COMMAND succeeds; fails the test with WHAT after 20 s
wait_for() {
  local what=$1 t; shift
  for ((t = 0; t < 2000; t++)); do "$@" && return 0; tick; done
  fail "$what did not happen in 20 s"
}
# The children run with VDBHAIR_TEST_STOP_AT_START=field: each stops itself (SIGSTOP) at its start,
# so the test signals a run that is certainly still running, or lets it go on (SIGCONT), in the
# order it chooses, on a fast machine or a slow one.
#   next_stopped BATCH_PID " PID PID ... "   # prints a stopped child of the batch not in the list
stopped_child() {
  local f c l more kids=()
  for f in /proc/"$1"/task/*/children; do
    more=(); read -r -a more 2>/dev/null < "$f"; kids+=("${more[@]}")
  done
  for c in "${kids[@]}"; do
    case "$2" in *" $c "*) continue ;; esac
    l=""; read -r l 2>/dev/null < "/proc/$c/stat"; l=${l##*) }
    [ "${l%% *}" = T ] && { echo "$c"; return 0; }
  done
  return 1
}
next_stopped() {
  local t
  for ((t = 0; t < 2000; t++)); do stopped_child "$1" "$2" && return 0; tick; done
  return 1
}
# Whether process $1 is gone or has SIGTERM pending (sent to it while it is stopped).
term_pending() {
  local k v
  while read -r k v; do
    [ "$k" = ShdPnd: ] && { [ $((0x$v & 0x4000)) -ne 0 ]; return; }
  done 2>/dev/null < "/proc/$1/status"
  return 0
}
recorded_at_least() { [ "$(lines "$1")" -ge "$2" ]; }
blocked_in_wait() { local w=""; read -r w 2>/dev/null < "/proc/$1/wchan"; [ "$w" = do_wait ]; }
# A batch started in the background with stopped children: if the test fails, they go with it.
bg=""
trap '[ -n "$bg" ] && kill -KILL $(pgrep -P "$bg") "$bg" 2>/dev/null' EXIT

# A batch killed by SIGNAL once AFTER inputs are recorded, resumed, against an uninterrupted run.
# Deterministic: exactly AFTER children are let go; the signal reaches the batch while it waits in
# wait4() for the next two, which are stopped (so the wait is what the signal interrupts), and those
# two go on only once the SIGTERM passed on to them (or PR_SET_PDEATHSIG's, after SIGKILL) is pending.
resume_case() {
  local signal=$1 n=4 after=2 jobs=2
  make_data $n; write_job
  "$cli" batch job.json -o ref --jobs $jobs --quiet || fail "the uninterrupted run failed"
  VDBHAIR_TEST_STOP_AT_START=field "$cli" batch job.json -o run --jobs $jobs --quiet &
  local pid=$! seen=" " waiting="" c i; bg=$pid
  for i in $(seq $after); do
    c=$(next_stopped $pid "$seen") || fail "no child $i of the batch stopped at its start in 20 s"
    # Each child starts with glibc's malloc on huge pages (ChildProcess.cc), the environment kept.
    tr '\0' '\n' < /proc/$c/environ | grep -q '^GLIBC_TUNABLES=\(.*:\)\?glibc.malloc.hugetlb=1' ||
      fail "child $c did not get GLIBC_TUNABLES=glibc.malloc.hugetlb=1: $(tr '\0' ' ' < /proc/$c/environ | grep -o 'GLIBC_TUNABLES=[^ ]*')"
    tr '\0' '\n' < /proc/$c/environ | grep -q '^VDBHAIR_TEST_STOP_AT_START=field$' || fail "child $c lost the batch's environment"
    seen="$seen$c "; kill -CONT "$c"
  done
  wait_for "$after records" recorded_at_least run/batch.jsonl $after
  for i in $(seq $jobs); do
    c=$(next_stopped $pid "$seen") || fail "the batch did not start $jobs more children after $after records"
    seen="$seen$c "; waiting="$waiting $c"
  done
  wait_for "the batch waiting for its children" blocked_in_wait $pid
  kill -"$signal" $pid
  for c in $waiting; do wait_for "SIGTERM passed on to child $c" term_pending "$c"; kill -CONT "$c" 2>/dev/null; done
  wait $pid; local status=$?; bg=""
  local done_before; done_before=$(lines run/batch.jsonl)
  echo "killed by SIG$signal with $done_before of $n inputs recorded (exit $status)"
  if [ "$signal" = TERM ]; then
    [ $status -eq 143 ] || fail "expected exit status 143 after SIGTERM, got $status"
  else
    [ $status -eq 137 ] || fail "expected the shell's 137 after SIGKILL, got $status"
  fi
  [ "$done_before" -eq $after ] || fail "expected the $after inputs let run recorded, and only those: $done_before"
  # The children die with the batch (SIGTERM forwarded, or PR_SET_PDEATHSIG after SIGKILL).
  for t in $(seq 100); do pgrep -f "$work/run/" >/dev/null || break; sleep 0.05; done
  ! pgrep -f "$work/run/" >/dev/null || fail "children of the killed batch still run"
  ! ls -a run | grep -q "vdbhair-tmp" || fail "a temporary output was left in run/: $(ls -a run)"
  "$cli" batch job.json -o run --jobs $jobs --json > resume.json 2> resume.err || fail "the resumed run failed: $(cat resume.err)"
  grep -q "\"skipped\":$done_before" resume.json || fail "the resumed run did not skip the $done_before recorded inputs: $(cat resume.json)"
  grep -q "\"ok\":$((n - done_before))" resume.json || fail "the resumed run did not run the other $((n - done_before)): $(cat resume.json)"
  local m; m=$(same_outputs ref run)
  [ "$(record_set ref/batch.jsonl)" = "$(record_set run/batch.jsonl | sed "s#/run/#/ref/#g")" ] || fail "the records differ from the uninterrupted run's"
  echo "ok: killed by SIG$signal after $done_before of $n, resumed: $m outputs identical to the uninterrupted run"
}

case "$case" in
resume-term) resume_case TERM ;;
resume-kill) resume_case KILL ;;
corrupt)
  make_data 2
  printf 'HAIRxxxx' > data/corrupt.hair
  printf 'data/style00.hair\n# a comment\n\ndata/corrupt.hair\ndata/missing.hair\ndata/style01.hair\n' > list.txt
  echo '{"inputs": {"list": "list.txt"}, "verb": "field", "args": ["--voxel-size", "2"], "output": "{stem}.vdb"}' > job.json
  "$cli" batch job.json -o out --jobs 2 --json > run1.json 2> run1.err; status=$?
  [ $status -eq 1 ] || fail "expected exit status 1 with failed inputs, got $status"
  grep -q '"ok":2,' run1.json && grep -q '"failed":2,' run1.json || fail "expected 2 ok and 2 failed: $(cat run1.json)"
  grep -q 'corrupt.hair.*"status":"failed"' out/batch.jsonl || fail "no failed record for corrupt.hair"
  grep '"input":"[^"]*corrupt.hair"' out/batch.jsonl | grep -q '"error":"vdbhair field: readHair([^)]*corrupt.hair): ' || fail "the corrupt input's record lacks its error: $(cat out/batch.jsonl)"
  grep '"input":"[^"]*missing.hair"' out/batch.jsonl | grep -q '"exit_code":1' || fail "the missing input's record lacks exit_code 1"
  grep -q "failed: .*corrupt.hair: vdbhair field: readHair" run1.err || fail "the summary does not list the failure: $(cat run1.err)"
  [ -f out/style00.vdb ] && [ -f out/style01.vdb ] && [ ! -e out/corrupt.vdb ] || fail "outputs: $(ls out)"
  "$cli" batch job.json -o out --jobs 2 --retry-failed --json > run2.json 2>/dev/null
  grep -q '"skipped":2,' run2.json && grep -q '"failed":2,' run2.json || fail "--retry-failed should rerun only the 2 failures: $(cat run2.json)"
  # A changed job (other args) does not count the old records.
  sed -i 's/"2"/"3"/' job.json
  "$cli" batch job.json -o out --jobs 2 --json > run3.json 2>/dev/null
  grep -q '"skipped":0,' run3.json && grep -q '"ok":2,' run3.json || fail "a changed job must run again: $(cat run3.json)"
  echo "ok: the corrupt and the missing input are recorded with their errors, the others written; --retry-failed reruns the failures only"
  ;;
crash)
  # Children that crash (SIGSEGV) and that are killed as the kernel's OOM killer kills (SIGKILL):
  # each is recorded with its cause, the batch goes on with the others, and --retry-failed
  # completes the set as an uninterrupted run does. (Children that run out of memory under an
  # address-space limit: the case out-of-memory.)
  ulimit -c 0
  make_data 4
  write_job
  "$cli" batch job.json -o ref --jobs 2 --quiet || fail "the clean run failed"
  # One child at a time (--jobs 1), each stopped at its start: the first gets SIGSEGV, the second
  # SIGKILL, the others go on.
  VDBHAIR_TEST_STOP_AT_START=field "$cli" batch job.json -o run --jobs 1 2> run.err &
  pid=$!; bg=$pid; seen=" "
  for sig in SEGV KILL CONT CONT; do
    c=$(next_stopped $pid "$seen") || fail "no new child of the batch (stopped at its start) to send SIG$sig to"
    seen="$seen$c "; kill -"$sig" "$c"
    [ $sig = SEGV ] && kill -CONT "$c"  # a stopped process takes SIGSEGV once it goes on
  done
  wait $pid; status=$?; bg=""
  [ $status -eq 1 ] || fail "expected exit status 1 with two children killed, got $status: $(cat run.err)"
  /usr/bin/python3 - run/batch.jsonl <<'PY' || fail "the records do not say what happened: $(cat run/batch.jsonl)"
import json, sys
rs = [json.loads(l) for l in open(sys.argv[1])]
by = sorted((r["index"], r["status"], r.get("signal_name"), r["error"]) for r in rs)
assert [b[1] for b in by] == ["failed", "failed", "ok", "ok"], by
assert by[0][2] == "SIGSEGV" and by[0][3] == "killed by SIGSEGV", by[0]
assert by[1][2] == "SIGKILL" and by[1][3] == "killed by SIGKILL (out of memory?)", by[1]
PY
  grep -q "killed by SIGSEGV" run.err && grep -q "killed by SIGKILL (out of memory?)" run.err || fail "the summary does not name the signals: $(cat run.err)"
  [ ! -e run/style00.vdb ] && [ ! -e run/style01.vdb ] || fail "a killed child left an output: $(ls run)"
  ! ls -a run | grep -q "vdbhair-tmp" || fail "a temporary output was left: $(ls -a run)"
  # Retrying the killed two completes the set.
  "$cli" batch job.json -o run --jobs 2 --retry-failed --json > retry.json 2> retry.err || fail "--retry-failed: $(cat retry.err)"
  grep -q '"ok":2,' retry.json && grep -q '"skipped":2,' retry.json || fail "--retry-failed should run the 2 killed inputs: $(cat retry.json)"
  m=$(same_outputs ref run)
  echo "ok: a child killed by SIGSEGV and one by SIGKILL recorded as such; retried: $m outputs identical to a clean run"
  ;;
out-of-memory)
  ulimit -c 0
  make_data 4
  # Out of memory: field at a voxel size that needs several GB, under a 200 MB address-space
  # limit that the batch and its children inherit (a child starts in about 110 MB of it at the
  # --threads 1 given here, which a many-core machine's share of its cores would not change).
  # Each child says so in one line and exits 1.
  # The same for a verb run alone, at limits around where its field stops fitting: OpenVDB frees a
  # grid with a vector it allocates, so without vdbhair's unwind reserve a child ended in
  # "terminate called after throwing an instance of 'std::bad_alloc'" (SIGABRT) at 250 MB.
  # Each run has its own limit and output, so they all run at once, with the batch.
  echo '{"inputs": "data/*.hair", "verb": "field", "args": ["--voxel-size", "0.1", "--threads", "1"], "output": "{stem}.vdb"}' > oom.json
  (ulimit -v 200000; exec "$cli" batch oom.json -o oom --jobs 2 --json > oom.out 2> oom.err) &
  oom=$!
  limits="150000 200000 250000 300000 350000"
  for lim in $limits; do
    (ulimit -v $lim; exec "$cli" field data/style00.hair -o alone$lim.vdb --voxel-size 0.5 --threads 2 --quiet > alone$lim.out 2>&1) &
    eval "alone$lim=\$!"
  done
  wait $oom; status=$?
  [ $status -eq 1 ] || fail "expected exit status 1 when every child runs out of memory, got $status: $(cat oom.err)"
  grep -q '"ok":0,' oom.out && grep -q '"failed":4,' oom.out || fail "expected 4 failures: $(cat oom.out)"
  [ "$(grep -c '"error":"vdbhair field: out of memory"' oom/batch.jsonl)" -eq 4 ] || fail "the records lack 'out of memory': $(cat oom/batch.jsonl)"
  ! grep -q "terminate called" oom.err || fail "a child aborted instead of reporting: $(cat oom.err)"
  for lim in $limits; do
    eval "wait \$alone$lim"; status=$?
    [ $status -eq 0 ] || { [ $status -eq 1 ] && [ "$(cat alone$lim.out)" = "vdbhair field: out of memory" ]; } ||
      fail "field under ulimit -v $lim: exit $status, $(head -c 300 alone$lim.out)"
  done
  ! ls -a . oom | grep -q "vdbhair-tmp" || fail "a temporary output was left: $(ls -a . oom)"
  echo "ok: 4 out-of-memory children of a batch reported in one line each, as field alone is under ulimit -v $limits"
  ;;
more-outputs)
  # A second output named in args ({outdir}/...) counts: a rerun after it is deleted runs that input again.
  make_data 2
  echo '{"inputs": "data/*.hair", "verb": "field", "args": ["--voxel-size", "2", "--dense", "{outdir}/{stem}.npy", "--dense-box", "-40,-10,-45,40,130,85", "--dense-size", "8,8,8"], "output": "{stem}.vdb"}' > job.json
  "$cli" batch job.json -o out --jobs 2 --quiet || fail "the first run failed"
  [ -f out/style00.npy ] && [ -f out/style01.npy ] || fail "no .npy written: $(ls out)"
  grep -q '"more_outputs":\["[^"]*/out/style00.npy"\]' out/batch.jsonl || fail "the record does not list the second output: $(cat out/batch.jsonl)"
  cp out/style01.npy style01.npy.first
  rm out/style01.npy
  "$cli" batch job.json -o out --jobs 2 --json > rerun.json 2> rerun.err || fail "the rerun failed: $(cat rerun.err)"
  grep -q '"ok":1,' rerun.json && grep -q '"skipped":1,' rerun.json || fail "the rerun should redo only the input whose .npy is gone: $(cat rerun.json)"
  cmp -s out/style01.npy style01.npy.first || fail "the rewritten .npy differs from the first"
  echo "ok: an input whose second output (.npy) was deleted runs again; the other is skipped"
  ;;
shard)
  make_data 5; write_job
  "$cli" batch job.json -o whole --jobs 2 --quiet || fail "the unsharded run failed"
  "$cli" batch job.json -o parts --shard 0/3 --jobs 1 --quiet || fail "shard 0/3"
  # Shard 1 from a Slurm array task's environment (an array 5-7: task 6 is shard 1 of 3).
  SLURM_ARRAY_TASK_ID=6 SLURM_ARRAY_TASK_MIN=5 SLURM_ARRAY_TASK_COUNT=3 "$cli" batch job.json -o parts --jobs 1 --quiet || fail "shard 1/3 from Slurm's variables"
  [ -f parts/batch.1-of-3.jsonl ] || fail "the Slurm task did not write batch.1-of-3.jsonl: $(ls parts)"
  "$cli" batch --merge parts > merge1.out 2> merge1.err; status=$?
  [ $status -eq 1 ] && grep -q "batch.2-of-3.jsonl missing" merge1.err || fail "--merge with a shard missing: exit $status, $(cat merge1.err)"
  "$cli" batch job.json -o parts --shard 2/3 --jobs 1 --quiet || fail "shard 2/3"
  [ "$(lines parts/batch.0-of-3.jsonl)" -eq 2 ] && [ "$(lines parts/batch.1-of-3.jsonl)" -eq 2 ] && [ "$(lines parts/batch.2-of-3.jsonl)" -eq 1 ] || fail "shards of 5 should hold 2, 2, 1"
  "$cli" batch --merge parts --json > merge.json || fail "--merge failed"
  grep -q '"inputs":5,"merged":3' merge.json || grep -q '"merged":3' merge.json || fail "merge summary: $(cat merge.json)"
  [ "$(record_set whole/batch.jsonl)" = "$(record_set parts/batch.jsonl | sed "s#/parts/#/whole/#g")" ] || fail "merged records differ from the unsharded run's"
  m=$(same_outputs whole parts)
  echo "ok: 3 shards (one from SLURM_ARRAY_TASK_*) merged equal the unsharded run: $m outputs, the same records"
  ;;
slurm)
  for p in slurmctld slurmd munged mungekey sbatch squeue; do
    command -v $p >/dev/null || { echo "SKIPPED: $p not found; install Debian's slurm-wlm to run the Slurm array test"; exit 0; }
  done
  # The cluster starts while the single-machine run runs (slurmctld's first scheduling pass comes
  # 3 s after its start, whatever is submitted before).
  "$src/tests/apps/slurm_cluster.sh" start "$work/cluster" > cluster.log 2>&1 &
  cluster=$!
  trap 'wait $cluster; "$src/tests/apps/slurm_cluster.sh" stop "$work/cluster"' EXIT
  make_data 4; write_job
  "$cli" batch job.json -o whole --jobs 2 --quiet || fail "the single-machine run failed"
  wait $cluster || fail "the one-node cluster did not start: $(cat cluster.log; tail -n 5 "$work"/cluster/log/* 2>/dev/null)"
  export SLURM_CONF=$work/cluster/slurm.conf
  jid=$(VDBHAIR=$cli sbatch --parsable --array=0-3 --export=ALL -o "$work/slurm-%a.log" -D "$work" "$src/scenes/batch/field.sbatch" job.json array) || fail "sbatch"
  for t in $(seq 600); do [ -z "$(squeue -h -j "$jid" 2>/dev/null)" ] && break; sleep 0.1; done
  [ -z "$(squeue -h -j "$jid" 2>/dev/null)" ] || fail "the array job did not finish in 60 s: $(squeue)"
  "$cli" batch --merge array --json > merge.json || fail "--merge of the array's shards: $(cat "$work"/slurm-*.log)"
  [ "$(record_set whole/batch.jsonl)" = "$(record_set array/batch.jsonl | sed "s#/array/#/whole/#g")" ] || fail "the array's records differ from the single machine's"
  m=$(same_outputs whole array)
  echo "ok: a 4-task Slurm array on a one-node cluster (127.0.0.1) equals the single-machine run: $m outputs"
  ;;
*) fail "unknown case $case" ;;
esac
