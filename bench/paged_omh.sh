#!/usr/bin/env bash
# Opening a large saved hierarchy with its points paged in on demand, against loading it whole
# and against reading its bytes, all in the same run: makes a big cloud from a real scan
# (omicron-cli tile), builds and saves its .omh, then runs bench/omh_paging_bench once per
# configuration (one process each: the peak RSS is the process's).
#
# usage: bench/paged_omh.sh [COPIES] [BUDGET ...]
#   COPIES of ../shared/data/autzen_south.ply (4.84 M points each; default 10 = 48 M points),
#   BUDGETs as the CLI takes them (default: 1G 256M). "whole" (no budget) runs first when the
#   points fit in half of the memory; its figures are the baseline.
#   e.g. bench/paged_omh.sh 40 4G 1G 256M       (194 M points, a 5 GB .omh)
# Scratch goes to $BENCH_DIR (default: a new folder under /tmp), removed at the end; the
# .omh is read from the page cache (it was just written), as after a save in the app.
# Lines: bench=paged_omh step=tile|build ... and bench=paged_omh mode=whole|paged budget=...
#        with omh_paging_bench's key=value figures.
set -euo pipefail
cd "$(dirname "$0")/.."
copies=${1:-10}
shift || true
budgets=("$@")
[ ${#budgets[@]} -eq 0 ] && budgets=(1G 256M)
source_cloud=../shared/data/autzen_south.ply
cli=build/release/bin/omicron-cli
bench=build/release/bin/omh_paging_bench
[ -x "$cli" ] && [ -x "$bench" ] || { echo "build first: ./scripts/build.sh" >&2; exit 1; }
[ -f "$source_cloud" ] || { echo "paged_omh: $source_cloud is absent" >&2; exit 77; }
work=$(mktemp -d "${BENCH_DIR:-/tmp}/omicron-paged-bench-XXXXXX")
trap 'rm -rf "$work"' EXIT

source bench/measure.sh

read -r wall _ _ rss < <(measure "$cli" tile "$source_cloud" "$work/big.ply" --copies "$copies")
points=$("$cli" info "$work/big.ply" | awk '/^points:/ { print $2 }')
echo "bench=paged_omh step=tile copies=$copies points=$points bytes=$(stat -c %s "$work/big.ply") wall_s=$wall peak_rss_mib=$((rss / 1024))"
read -r wall _ _ rss < <(measure "$cli" build "$work/big.ply" --store packed --save "$work/big.omh")
rm -f "$work/big.ply"
echo "bench=paged_omh step=build points=$points omh_bytes=$(stat -c %s "$work/big.omh") wall_s=$wall peak_rss_mib=$((rss / 1024))"

half_kib=$(awk '/MemTotal/ { print int($2 / 2) }' /proc/meminfo)
omh_kib=$(( $(stat -c %s "$work/big.omh") / 1024 ))
configs=()
[ "$omh_kib" -lt "$half_kib" ] && configs=(whole)
configs+=("${budgets[@]}")
for config in "${configs[@]}"; do
  if [ "$config" = whole ]; then
    flags=(--whole)
  else
    flags=(--budget "$config")
  fi
  "$bench" "$work/big.omh" "${flags[@]}" > "$work/bench.txt"
  echo "bench=paged_omh budget=$config $(grep -v '^file=\|^bench=' "$work/bench.txt" | tr '\n' ' ')"
done
