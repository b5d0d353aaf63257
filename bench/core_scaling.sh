#!/usr/bin/env bash
# The whole pipeline's speed-up from one core to two: `omicron-cli build --save` of the same LAS
# file as a process pinned (taskset) to one core, then to the first two, alternating run by
# run, on a tmpfs (/dev/shm) so the disk is out of the comparison. Pinning the process, not
# only oneTBB (--threads 1), is the honest single-core baseline: the reader, the sorter's
# consumer and the save's writer have threads of their own. Prints one line per run and a
# summary with the medians and the ratio.
#
# usage: bench/core_scaling.sh CLOUD [--copies K] [--runs N]
#   CLOUD    a PLY, LAS or LAZ file, tiled K times (default 1) into one LAS 1.2 file
#            (omicron-cli tile); K = 5 makes 24.2 M points from autzen_south.
#   --runs N runs on each core count (default 5); the summary takes medians.
# Lines: bench=core_scaling cores=1|2 run=R points=P wall_s= user_s= sys_s= peak_rss_mib=
#        bench=core_scaling summary points=P one_core_wall_s= two_cores_wall_s= speedup=
set -euo pipefail
cd "$(dirname "$0")/.."
source bench/measure.sh
copies=1 runs=5
parse_cloud_args core_scaling "" "$@"
[ "$(nproc)" -ge 2 ] || { echo "core_scaling: needs two cores" >&2; exit 77; }
tile_input core-scaling "$cloud" "$copies"
echo "bench=core_scaling step=input cloud=$(basename "$cloud") copies=$copies points=$points"

declare -A walls
for run in $(seq 1 "$runs"); do
  for cores in 1 2; do
    read -r wall user sys rss < <(measure_build core_scaling taskset -c "0-$((cores - 1))")
    echo "bench=core_scaling cores=$cores run=$run points=$points wall_s=$wall user_s=$user sys_s=$sys peak_rss_mib=$((rss / 1024))"
    walls[$cores]+="$wall "
  done
done

one=$(echo "${walls[1]}" | median)
two=$(echo "${walls[2]}" | median)
awk -v p="$points" -v o="$one" -v t="$two" 'BEGIN {
  printf "bench=core_scaling summary points=%d one_core_wall_s=%.2f two_cores_wall_s=%.2f speedup=%.2f\n", p, o, t, o / t }'
