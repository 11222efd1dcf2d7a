#!/usr/bin/env bash
# Times a dataset through `vdbhair field` three ways (issue 21's measure): the shell loop a user
# writes today (one process per file, one after another, each with every core), and
# `vdbhair batch` with --jobs 1, 2, ... up to twice the cores (JOBS="1 2 4" to choose). Prints the
# wall time, the time per file and the throughput of each, and the scaling of batch's throughput
# with jobs: it should grow until the cores are used and then stay flat.
#   scripts/bench_batch.sh [DATA_GLOB] [VDBHAIR]
# DATA_GLOB defaults to the 343 five-guide USC-HairSalon styles in ../shared (absolute, quoted);
# VDBHAIR to build/bin/vdbhair. Extra field options: FIELD_ARGS="--voxel-size 0.01" (the default).
# Work happens in a scratch folder that is removed at the end. Speed is measured here, never in tests.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
glob=${1:-$root/../shared/data/hair/usc_data/hairnet_cstrands/*.data}
cli=$(realpath "${2:-$root/build/bin/vdbhair}")
field_args=${FIELD_ARGS:---voxel-size 0.01}
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
# shellcheck disable=SC2206
files=($glob)
[ -f "${files[0]}" ] || { echo "bench_batch.sh: no file matches $glob" >&2; exit 1; }
# Normalized paths (no "..") as batch records them: the field's vdbhair_source metadata names the input.
mapfile -t files < <(realpath -s "${files[@]}")
n=${#files[@]}
printf '%s\n' "${files[@]}" > "$work/list.txt"
args_json=$(printf '"%s",' $field_args); args_json="[${args_json%,}]"
echo "{\"inputs\": {\"list\": \"list.txt\"}, \"verb\": \"field\", \"args\": $args_json, \"output\": \"{stem}.vdb\"}" > "$work/job.json"
now() { date +%s.%N; }
report() {  # name seconds
  awk -v name="$1" -v s="$2" -v n="$n" 'BEGIN { printf "%-28s %8.2f s  %7.1f ms/file  %6.2f files/s\n", name, s, 1000 * s / n, n / s }'
}
echo "bench_batch.sh: $n files through 'vdbhair field $field_args' on $(nproc) cores ($(uptime | sed 's/.*load average: //') load)"

mkdir -p "$work/loop"
t0=$(now)
for f in "${files[@]}"; do
  b=$(basename "$f"); "$cli" field "$f" -o "$work/loop/${b%.*}.vdb" $field_args --quiet || true
done
loop=$(echo "$(now) - $t0" | bc)
report "shell loop (sequential)" "$loop"

cores=$(nproc)
job_counts=${JOBS:-$(j=1; while [ "$j" -le $((2 * cores)) ]; do printf '%s ' "$j"; j=$((2 * j)); done)}
case " $job_counts " in *" 1 "*) ;; *) job_counts="1 $job_counts";; esac
case " $job_counts " in *" 2 "*) ;; *) job_counts="$job_counts 2";; esac
for jobs in $job_counts; do
  t0=$(now)
  "$cli" batch "$work/job.json" -o "$work/batch$jobs" --jobs $jobs --quiet || true
  s=$(echo "$(now) - $t0" | bc)
  report "batch --jobs $jobs" "$s"
  eval "batch$jobs=$s"
  [ "$jobs" = 1 ] || awk -v b1="$batch1" -v s="$s" -v j="$jobs" -v c="$cores" \
    'BEGIN { printf "  --jobs %d vs --jobs 1: %.2fx the throughput (%d cores)\n", j, b1 / s, c }'
done
# Each batch's outputs equal the loop's (after the .vdb header's random UUID).
for f in "$work"/loop/*.vdb; do
  cmp -s -i 57 "$f" "$work/batch2/$(basename "$f")" || { echo "bench_batch.sh: $(basename "$f") differs between the loop and batch" >&2; exit 1; }
done
awk -v l="$loop" -v b1="$batch1" -v b2="$batch2" 'BEGIN {
  printf "batch --jobs 1 vs the loop: %.2fx the per-file time; --jobs 2 vs --jobs 1: %.2fx the throughput; --jobs 2 vs the loop: %.2fx\n", b1 / l, b1 / b2, l / b2 }'
peak=$(/usr/bin/python3 -c "import json,sys; print(max(json.loads(l)['peak_rss_kb'] for l in open(sys.argv[1])))" "$work/batch2/batch.jsonl")
echo "largest process: $((peak / 1024)) MiB; every output identical to the loop's"
