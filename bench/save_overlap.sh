#!/usr/bin/env bash
# Whether `build --save` writes the .omh at disk speed, overlapped with the build: the same LAS
# input (on a tmpfs, so reading it is not the disk's work) built three ways, alternating run by
# run as whole processes (the disk's runs first, then the build and the save in alternating
# order): `omicron-cli build` without a save (read + sort + build), `dd` of the
# same .omh bytes into the output folder, through the page cache with an fsync at the end and,
# where the folder allows it, with direct I/O (the disk's time for them: the shorter of the
# two), and `omicron-cli build --save` into that folder (which also fsyncs before its rename).
# The save is at disk speed, overlapped, when it takes little more than the longer of the
# build and the disk's time. Prints one line per run and a summary with the medians and
# ratio = save / max(build, disk).
#
# The floor under that ratio: no byte of the .omh is known before the read phase ends (the
# deepest level is the sorted cloud, and the sorter's first chunk is complete only once the
# last point is read; the tables and upper levels come later still), so a save takes at least
# the read phase (`read_s` of the save's own `--json`) plus the disk's time for the whole file,
# and at least the build: floor = max(build, read + disk), floor_ratio = floor / max(build,
# disk). Where floor_ratio is above 1.2, no save of this file format meets ratio 1.2 on that
# disk, whatever it overlaps.
#
# usage: bench/save_overlap.sh CLOUD [--copies K] [--runs N] [--dir DIR]
#   CLOUD    a PLY, LAS or LAZ file, tiled K times (default 1) into one LAS 1.2 file
#            (omicron-cli tile); K = 5 makes 24.2 M points from autzen_south.
#   --runs N runs of each (default 3); the summary takes medians.
#   --dir D  the output folder (default /var/tmp: a disk). On a tmpfs (/dev/shm) the "disk" is
#            memory and the write is CPU time on the same cores as the build.
# Lines: bench=save_overlap step=build|dd|dd_direct|save run=R points=P wall_s= user_s=
#        sys_s= peak_rss_mib= ; bench=save_overlap summary points=P omh_bytes= build_wall_s=
#        dd_wall_s= dd_direct_wall_s= (or none) save_wall_s= ratio= read_s= floor_s=
#        floor_ratio=  (a save's line also has read_s= and after_read_s=, its wall time after it)
set -euo pipefail
cd "$(dirname "$0")/.."
source bench/measure.sh
copies=1 runs=3 dir=/var/tmp
parse_cloud_args save_overlap "dir" "$@"
[ -d "$dir" ] && [ -w "$dir" ] || { echo "save_overlap: $dir is not a writable folder" >&2; exit 2; }
tile_input save-overlap "$cloud" "$copies"
out=$(mktemp -d "$dir/omicron-save-overlap-XXXXXX")
trap 'rm -rf "$work" "$out"' EXIT
# The bytes dd writes: one save's .omh, kept on the tmpfs beside the input.
"$cli" build "$input" --save "$work/reference.omh" > /dev/null
bytes=$(stat -c %s "$work/reference.omh")
# Direct I/O (a tmpfs refuses it) is tried once.
disk_steps="dd"
if dd if="$work/reference.omh" of="$out/out.omh" bs=4M count=1 oflag=direct status=none 2> /dev/null; then
  disk_steps="dd dd_direct"
fi
echo "bench=save_overlap step=input cloud=$(basename "$cloud") copies=$copies points=$points omh_bytes=$bytes dir=$dir fs=$(stat -f -c %T "$out")"

declare -A walls
for run in $(seq 1 "$runs"); do
  # The save used to come right after the dd runs and alone paid the host's slow phase.
  for step in $disk_steps $(in_turn "$run" build save); do
    rm -f "$out/out.omh"
    case $step in
      build) read -r wall user sys rss < <(measure "$cli" build "$input") ;;
      dd) read -r wall user sys rss < <(measure dd if="$work/reference.omh" of="$out/out.omh" bs=4M conv=fsync status=none) ;;
      dd_direct) read -r wall user sys rss < <(measure dd if="$work/reference.omh" of="$out/out.omh" bs=4M oflag=direct conv=fsync status=none) ;;
      save) read -r wall user sys rss < <(measure "$cli" build "$input" --save "$out/out.omh" --json) ;;
    esac
    if [ "$step" != build ] && [ "$(stat -c %s "$out/out.omh" 2> /dev/null)" != "$bytes" ]; then
      echo "save_overlap: $step did not write the $bytes bytes:" >&2
      cat "$work/err.txt" >&2
      exit 1
    fi
    extra=
    if [ "$step" = save ]; then
      read_s=$(json_field read_s "$work/out.txt")
      [ -n "$read_s" ] || { echo "save_overlap: the save printed no read_s" >&2; exit 1; }
      extra=$(awk -v r="$read_s" -v w="$wall" 'BEGIN { printf " read_s=%.3f after_read_s=%.3f", r, w - r }')
      walls[read_phase]+="$read_s "
    fi
    echo "bench=save_overlap step=$step run=$run points=$points wall_s=$wall user_s=$user sys_s=$sys peak_rss_mib=$((rss / 1024))$extra"
    walls[$step]+="$wall "
  done
done

build=$(echo "${walls[build]}" | median)
dd=$(echo "${walls[dd]}" | median)
direct=none
[ -n "${walls[dd_direct]:-}" ] && direct=$(echo "${walls[dd_direct]}" | median)
save=$(echo "${walls[save]}" | median)
read_phase=$(echo "${walls[read_phase]}" | median)
awk -v p="$points" -v b="$bytes" -v bw="$build" -v dw="$dd" -v xw="$direct" -v sw="$save" -v rs="$read_phase" 'BEGIN {
  disk = (xw != "none" && xw + 0 < dw + 0) ? xw : dw
  longer = (bw > disk) ? bw : disk
  floor = (bw > rs + disk) ? bw : rs + disk
  printf "bench=save_overlap summary points=%d omh_bytes=%d build_wall_s=%.2f dd_wall_s=%.2f dd_direct_wall_s=%s save_wall_s=%.2f ratio=%.2f read_s=%.2f floor_s=%.2f floor_ratio=%.2f\n",
         p, b, bw, dw, (xw == "none") ? xw : sprintf("%.2f", xw), sw, sw / longer, rs, floor, floor / longer }'
