#!/usr/bin/env bash
# Whether `build --save` writes the .omh at disk speed, overlapped with the build: the same LAS
# input (on a tmpfs, so reading it is not the disk's work) built three ways, alternating run by
# run as whole processes: `omicron-cli build` without a save (read + sort + build), `dd` of the
# same .omh bytes into the output folder, through the page cache with an fsync at the end and,
# where the folder allows it, with direct I/O (the disk's time for them: the shorter of the
# two), and `omicron-cli build --save` into that folder (which also fsyncs before its rename).
# The save is at disk speed, overlapped, when it takes little more than the longer of the
# build and the disk's time. Prints one line per run and a summary with the medians and
# ratio = save / max(build, disk).
#
# usage: bench/save_overlap.sh CLOUD [--copies K] [--runs N] [--dir DIR]
#   CLOUD    a PLY, LAS or LAZ file, tiled K times (default 1) into one LAS 1.2 file
#            (omicron-cli tile); K = 5 makes 24.2 M points from autzen_south.
#   --runs N runs of each (default 3); the summary takes medians.
#   --dir D  the output folder (default /var/tmp: a disk). On a tmpfs (/dev/shm) the "disk" is
#            memory and the write is CPU time on the same cores as the build.
# Lines: bench=save_overlap step=build|dd|dd_direct|save run=R points=P wall_s= user_s=
#        sys_s= peak_rss_mib= ; bench=save_overlap summary points=P omh_bytes= build_wall_s=
#        dd_wall_s= dd_direct_wall_s= (or none) save_wall_s= ratio=
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
steps="build dd save"
if dd if="$work/reference.omh" of="$out/out.omh" bs=4M count=1 oflag=direct status=none 2> /dev/null; then
  steps="build dd dd_direct save"
fi
echo "bench=save_overlap step=input cloud=$(basename "$cloud") copies=$copies points=$points omh_bytes=$bytes dir=$dir fs=$(stat -f -c %T "$out")"

declare -A walls
for run in $(seq 1 "$runs"); do
  for step in $steps; do
    rm -f "$out/out.omh"
    case $step in
      build) read -r wall user sys rss < <(measure "$cli" build "$input") ;;
      dd) read -r wall user sys rss < <(measure dd if="$work/reference.omh" of="$out/out.omh" bs=4M conv=fsync status=none) ;;
      dd_direct) read -r wall user sys rss < <(measure dd if="$work/reference.omh" of="$out/out.omh" bs=4M oflag=direct conv=fsync status=none) ;;
      save) read -r wall user sys rss < <(measure "$cli" build "$input" --save "$out/out.omh") ;;
    esac
    if [ "$step" != build ] && [ "$(stat -c %s "$out/out.omh" 2> /dev/null)" != "$bytes" ]; then
      echo "save_overlap: $step did not write the $bytes bytes:" >&2
      cat "$work/err.txt" >&2
      exit 1
    fi
    echo "bench=save_overlap step=$step run=$run points=$points wall_s=$wall user_s=$user sys_s=$sys peak_rss_mib=$((rss / 1024))"
    walls[$step]+="$wall "
  done
done

build=$(echo "${walls[build]}" | median)
dd=$(echo "${walls[dd]}" | median)
direct=none
[ -n "${walls[dd_direct]:-}" ] && direct=$(echo "${walls[dd_direct]}" | median)
save=$(echo "${walls[save]}" | median)
awk -v p="$points" -v b="$bytes" -v bw="$build" -v dw="$dd" -v xw="$direct" -v sw="$save" 'BEGIN {
  disk = (xw != "none" && xw + 0 < dw + 0) ? xw : dw
  longer = (bw > disk) ? bw : disk
  printf "bench=save_overlap summary points=%d omh_bytes=%d build_wall_s=%.2f dd_wall_s=%.2f dd_direct_wall_s=%s save_wall_s=%.2f ratio=%.2f\n",
         p, b, bw, dw, (xw == "none") ? xw : sprintf("%.2f", xw), sw, sw / longer }'
