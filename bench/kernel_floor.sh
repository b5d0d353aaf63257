#!/usr/bin/env bash
# How far the kernel time of `build --save` is above what the same job cannot avoid on this
# machine, measured in the same run, alternating run by run as whole processes, on a tmpfs (the
# dd steps first, then ours and the memory step back to back in alternating order):
#   ours    omicron-cli build IN.las --save OUT.omh
#   read    dd of IN.las to /dev/null: the input's bytes out of the page cache (the copy the
#           reader's read() makes; a mapped file costs its faults instead, about the same here)
#   write   dd of the .omh's bytes into a new file on the tmpfs (new page-cache pages), less
#   omh_read  dd of the same .omh to /dev/null (what that dd spent reading them)
#   memory  page_cost_bench --populate-only: ours's peak resident set faulted in by one
#           MADV_POPULATE_WRITE, the cheapest way to touch that much fresh memory (small pages:
#           src/core/points/huge_page_policy.hpp says why)
# floor_sys_s = read + (write - omh_read) + memory (system time each). floor_share = floor_sys_s /
# (ours_user_s + floor_sys_s): the kernel share of a build that spent no system time beyond
# the floor and as much user time as ours; no build doing this job with our user time gets
# below it. ours_share = ours_sys_s / (ours_user_s + ours_sys_s).
#
# usage: bench/kernel_floor.sh CLOUD [--copies K] [--runs N]
#   CLOUD    a PLY, LAS or LAZ file, tiled K times (default 1) into one LAS 1.2 file
#            (omicron-cli tile); K = 5 makes 24.2 M points from autzen_south.
# Lines: bench=kernel_floor step=ours|read|write|omh_read|memory run=R wall_s= user_s= sys_s=
#        peak_rss_mib= ; bench=kernel_floor summary points= ours_user_s= ours_sys_s=
#        read_sys_s= write_sys_s= memory_sys_s= floor_sys_s= ours_share= floor_share=
#        ours_over_floor_sys=   (medians)
set -euo pipefail
cd "$(dirname "$0")/.."
source bench/measure.sh
copies=1 runs=3
parse_cloud_args kernel_floor "" "$@"
page_cost=build/release/bin/page_cost_bench
[ -x "$page_cost" ] || { echo "kernel_floor: build $page_cost first (cmake --build --preset release)" >&2; exit 2; }
tile_input kernel-floor "$cloud" "$copies"
# The bytes dd writes and the resident set the memory step touches: one build's.
read -r _ _ _ peak_kib < <(measure_build kernel_floor)
cp "$work/out.omh" "$work/reference.omh"
peak_mib=$(((peak_kib + 1023) / 1024))
echo "bench=kernel_floor step=input cloud=$(basename "$cloud") copies=$copies points=$points bytes=$(stat -c %s "$input") omh_bytes=$(stat -c %s "$work/reference.omh") peak_rss_mib=$peak_mib"

ours_users=""
declare -A syss
for run in $(seq 1 "$runs"); do
  # The memory step used to come right after the dd runs and alone paid the host's slow
  # phase, which raised the floor.
  for step in read write omh_read $(in_turn "$run" ours memory); do
    case $step in
      ours) read -r wall user sys rss < <(measure_build kernel_floor) ;;
      read) read -r wall user sys rss < <(measure dd if="$input" of=/dev/null bs=1M status=none) ;;
      omh_read) read -r wall user sys rss < <(measure dd if="$work/reference.omh" of=/dev/null bs=4M status=none) ;;
      write)
        rm -f "$work/copy.omh"
        read -r wall user sys rss < <(measure dd if="$work/reference.omh" of="$work/copy.omh" bs=4M status=none)
        rm -f "$work/copy.omh" ;;
      memory) read -r wall user sys rss < <(measure "$page_cost" --mib "$peak_mib" --populate-only) ;;
    esac
    echo "bench=kernel_floor step=$step run=$run wall_s=$wall user_s=$user sys_s=$sys peak_rss_mib=$((rss / 1024))"
    [ "$step" = ours ] && ours_users+="$user "
    syss[$step]+="$sys "
  done
done

declare -A sys_median
for step in "${!syss[@]}"; do
  sys_median[$step]=$(echo "${syss[$step]}" | median)
done
awk -v p="$points" -v u="$(echo "$ours_users" | median)" -v s="${sys_median[ours]}" \
    -v r="${sys_median[read]}" -v w="${sys_median[write]}" -v o="${sys_median[omh_read]}" \
    -v m="${sys_median[memory]}" 'BEGIN {
  w = (w > o) ? w - o : 0
  floor = r + w + m
  printf "bench=kernel_floor summary points=%d ours_user_s=%.2f ours_sys_s=%.2f read_sys_s=%.2f write_sys_s=%.2f memory_sys_s=%.2f floor_sys_s=%.2f ours_share=%.2f floor_share=%.2f ours_over_floor_sys=%.2f\n",
         p, u, s, r, w, m, floor, s / (u + s), floor / (u + floor), s / floor }'
