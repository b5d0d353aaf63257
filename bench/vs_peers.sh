#!/usr/bin/env bash
# omicron against PotreeConverter 2 on the same LAS input, in the same run, as whole processes:
# `omicron-cli build --save` (read, sort, build, write the .omh) and `PotreeConverter -m random`
# (its fastest sampling), alternating run by run so that both see the same machine state, on a
# tmpfs (/dev/shm) so the disk is out of the comparison. Prints one line per run and a summary
# with the medians, the speed ratio and both peak resident sets.
#
# usage: bench/vs_peers.sh CLOUD [--copies K] [--runs N] [--keep-input]
#   CLOUD    a PLY, LAS or LAZ file (e.g. ../shared/data/autzen_south.ply, 4.84 M points); it is
#            tiled K times (default 1) into one LAS 1.2 file (omicron-cli tile), which both
#            tools read. K = 6 makes 29 M points from autzen_south.
#   --runs N runs of each tool (default 3); the summary takes medians.
# Needs PotreeConverter built as ../shared/peers/run-peers.sh's header says
# ($POTREE, default ~/peers/PotreeConverter/build/PotreeConverter) and GNU time.
# Lines: bench=vs_peers tool=omicron|potree_random run=R points=P wall_s= user_s= sys_s=
#        peak_rss_mib= ; bench=vs_peers summary ... speedup=(potree / omicron wall time)
set -euo pipefail
cd "$(dirname "$0")/.."
source bench/measure.sh
copies=1 runs=3
parse_cloud_args vs_peers "" "$@"
potree=${POTREE:-$HOME/peers/PotreeConverter/build/PotreeConverter}
[ -x "$potree" ] || { echo "vs_peers: PotreeConverter not found at $potree (see ../shared/peers/run-peers.sh)" >&2; exit 77; }
tile_input vs-peers "$cloud" "$copies"
echo "bench=vs_peers step=input cloud=$(basename "$cloud") copies=$copies points=$points bytes=$(stat -c %s "$input")"

declare -A walls rsss
for run in $(seq 1 "$runs"); do
  for tool in omicron potree_random; do
    rm -rf "$work/out" "$work/out.omh"
    if [ "$tool" = omicron ]; then
      read -r wall user sys rss < <(measure "$cli" build "$input" --save "$work/out.omh")
    else
      read -r wall user sys rss < <(measure "$potree" "$input" -o "$work/out" -m random)
    fi
    [ -s "$work/out.omh" ] || [ -s "$work/out/octree.bin" ] ||
      { echo "vs_peers: $tool wrote nothing:" >&2; cat "$work/err.txt" >&2; exit 1; }
    echo "bench=vs_peers tool=$tool run=$run points=$points wall_s=$wall user_s=$user sys_s=$sys peak_rss_mib=$((rss / 1024))"
    walls[$tool]+="$wall "
    rsss[$tool]+="$((rss / 1024)) "
  done
done

ours=$(echo "${walls[omicron]}" | median)
theirs=$(echo "${walls[potree_random]}" | median)
our_rss=$(echo "${rsss[omicron]}" | median)
their_rss=$(echo "${rsss[potree_random]}" | median)
awk -v p="$points" -v o="$ours" -v t="$theirs" -v orss="$our_rss" -v trss="$their_rss" 'BEGIN {
  printf "bench=vs_peers summary points=%d omicron_wall_s=%.2f potree_random_wall_s=%.2f speedup=%.2f omicron_peak_rss_mib=%d potree_peak_rss_mib=%d rss_ratio=%.2f\n",
         p, o, t, t / o, orss, trss, orss / trss }'
