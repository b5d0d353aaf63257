#!/usr/bin/env bash
# The whole out-of-core path on a cloud tiled from a real scan, as a user runs it: for each
# memory budget, `omicron-cli build --memory-budget B --save` as a whole process (wall time,
# points/s, peak resident set, bytes written beside the saved file: the scratch traffic),
# then the saved hierarchy opened under the same budget (bench/omh_paging_bench: first pixels,
# full detail of close-ups, peak resident set). Baselines in the same run: reading the tiled
# file (cat), and where the machine has the memory, the build without a budget and the saved
# hierarchy loaded whole (omh_paging_bench --whole, which also times reading its bytes).
#
# usage: bench/out_of_core.sh COPIES [BUDGET ...]     (default budgets: 4G 1G)
#   COPIES of ../shared/data/autzen_south.ply, 4.84 M points each: 10 = 48 M, 41 = 199 M,
#   207 = 1.0 B points (a 15 GB PLY, a 26 GB .omh and a 17 GB scratch cloud at once: about
#   60 GB of disk).
# Scratch goes to $BENCH_DIR (default: a new folder under /tmp), removed at the end.
# Lines: bench=out_of_core step=tile|read|build|open budget=... key=value ...
set -euo pipefail
cd "$(dirname "$0")/.."
copies=${1:?usage: bench/out_of_core.sh COPIES [BUDGET ...]}
shift
budgets=("$@")
[ ${#budgets[@]} -eq 0 ] && budgets=(4G 1G)
source_cloud=../shared/data/autzen_south.ply
cli=build/release/bin/omicron-cli
bench=build/release/bin/omh_paging_bench
[ -x "$cli" ] && [ -x "$bench" ] || { echo "build first: ./scripts/build.sh" >&2; exit 1; }
[ -f "$source_cloud" ] || { echo "out_of_core: $source_cloud is absent" >&2; exit 77; }
work=$(mktemp -d "${BENCH_DIR:-/tmp}/omicron-out-of-core-XXXXXX")
trap 'rm -rf "$work"' EXIT
source bench/measure.sh

# Bytes a finished process wrote (its "File system outputs", 512-byte blocks).
written_bytes() { awk -F': ' '/File system outputs/ { printf "%.0f\n", $2 * 512 }' "$work/time.txt"; }

read -r wall _ _ rss < <(measure "$cli" tile "$source_cloud" "$work/big.ply" --copies "$copies")
points=$(points_in "$work/big.ply")
bytes=$(stat -c %s "$work/big.ply")
echo "bench=out_of_core step=tile copies=$copies points=$points bytes=$bytes wall_s=$wall peak_rss_mib=$((rss / 1024))"
read -r wall _ _ rss < <(measure sh -c "cat '$work/big.ply' > /dev/null")
echo "bench=out_of_core step=read budget=none bytes=$bytes wall_s=$wall"

configs=()
# An in-memory build keeps about 45 bytes a point at its peak.
half_bytes=$(awk '/MemTotal/ { printf "%.0f\n", $2 * 512 }' /proc/meminfo)
[ $((points * 45)) -lt "$half_bytes" ] && configs=(none)
configs+=("${budgets[@]}")
for budget in "${configs[@]}"; do
  flags=()
  [ "$budget" != none ] && flags=(--memory-budget "$budget" --temp-dir "$work")
  read -r wall user sys rss < <(measure "$cli" build "$work/big.ply" "${flags[@]}" --save "$work/big.omh")
  omh=$(stat -c %s "$work/big.omh")
  scratch=$(( $(written_bytes) - omh ))
  rate=$(awk -v p="$points" -v w="$wall" 'BEGIN { printf "%.1f", p / w / 1e6 }')
  echo "bench=out_of_core step=build budget=$budget points=$points wall_s=$wall user_s=$user sys_s=$sys mpoints_per_s=$rate peak_rss_mib=$((rss / 1024)) omh_bytes=$omh scratch_written_bytes=$scratch"
  if [ "$budget" = none ]; then
    "$bench" "$work/big.omh" --whole > "$work/bench.txt"
  else
    "$bench" "$work/big.omh" --budget "$budget" > "$work/bench.txt"
  fi
  echo "bench=out_of_core step=open budget=$budget $(grep -v '^file=\|^bench=' "$work/bench.txt" | tr '\n' ' ')"
  rm -f "$work/big.omh"
done
