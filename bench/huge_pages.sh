#!/usr/bin/env bash
# Huge pages against small ones for the whole `omicron-cli build --save` (OMICRON_HUGE_PAGES=1
# and =0, alternating run by run, on a tmpfs so the disk is out of the comparison), each run
# after an idle pause: the state a build usually starts from. It checks the choice
# points/huge_page_policy.hpp makes for this machine (huge pages, unless free memory is
# reported to a hypervisor and small pages measure cheaper there). Prints one line per run and
# a summary with the medians, the ratio and what the policy picks here.
#
# usage: bench/huge_pages.sh CLOUD [--copies K] [--runs N] [--idle S]
#   CLOUD    a PLY, LAS or LAZ file, tiled K times (default 1) into one LAS 1.2 file
#            (omicron-cli tile); K = 5 makes 24.2 M points from autzen_south.
#   --runs N runs with each page size (default 3); --idle S seconds before each (default 5).
# Lines: bench=huge_pages pages=huge|small run=R points=P wall_s= user_s= sys_s= peak_rss_mib=
#        bench=huge_pages summary points=P huge_wall_s= small_wall_s= small_speedup=
#        reported_kib= policy=huge|small
set -euo pipefail
cd "$(dirname "$0")/.."
source bench/measure.sh
copies=1 runs=3 idle=5
parse_cloud_args huge_pages "idle" "$@"
tile_input huge-pages "$cloud" "$copies"
echo "bench=huge_pages step=input cloud=$(basename "$cloud") copies=$copies points=$points"

declare -A walls
for run in $(seq 1 "$runs"); do
  for pages in huge small; do
    sleep "$idle"
    flag=$([ "$pages" = huge ] && echo 1 || echo 0)
    read -r wall user sys rss < <(measure_build huge_pages env OMICRON_HUGE_PAGES="$flag")
    echo "bench=huge_pages pages=$pages run=$run points=$points wall_s=$wall user_s=$user sys_s=$sys peak_rss_mib=$((rss / 1024))"
    walls[$pages]+="$wall "
  done
done

huge=$(echo "${walls[huge]}" | median)
small=$(echo "${walls[small]}" | median)
reported=$(cat /sys/module/page_reporting/parameters/reported_kib 2>/dev/null || echo 0)
# What the policy picks with no override (where reporting is active it measures, per process).
policy=$("$cli" build "$input" --json | json_field pages -)
awk -v p="$points" -v h="$huge" -v s="$small" -v r="$reported" -v pol="$policy" 'BEGIN {
  printf "bench=huge_pages summary points=%d huge_wall_s=%.2f small_wall_s=%.2f small_speedup=%.2f reported_kib=%s policy=%s\n", p, h, s, h / s, r, pol }'
