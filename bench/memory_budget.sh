#!/usr/bin/env bash
# Sorting and building beyond the memory budget, as whole processes: peak resident set and
# wall time of `omicron-cli sort` and `build` under each budget, against the same commands
# without a budget (in memory) and against copying the input's bytes (cat IN > OUT: the raw
# I/O floor of reading the cloud and writing a file of its size), all in the same run.
#
# usage: bench/memory_budget.sh IN [BUDGET ...]     (default budgets: 1G 256M)
#   e.g. omicron-cli tile ../shared/data/autzen_south.ply /tmp/south10.ply --copies 10
#        bench/memory_budget.sh /tmp/south10.ply 1G 512M 256M
# Scratch goes to $BENCH_DIR (default: a new folder under /tmp), removed at the end.
# Lines: bench=memory_budget command=sort|build budget=... wall_s= user_s= sys_s=
#        peak_rss_mib= sort_runs= ...; and one bench=memory_budget command=copy line.
set -euo pipefail
cd "$(dirname "$0")/.."
input=${1:?usage: bench/memory_budget.sh IN [BUDGET ...]}
shift
budgets=("$@")
[ ${#budgets[@]} -eq 0 ] && budgets=(1G 256M)
cli=build/release/bin/omicron-cli
[ -x "$cli" ] || { echo "build first: ./scripts/build.sh" >&2; exit 1; }
work=$(mktemp -d "${BENCH_DIR:-/tmp}/omicron-memory-bench-XXXXXX")
trap 'rm -rf "$work"' EXIT

source bench/measure.sh

points=$(points_in "$input")
read -r wall user sys rss < <(measure sh -c "cat '$input' > '$work/copy'")
rm -f "$work/copy"
echo "bench=memory_budget command=copy points=$points bytes=$(stat -c %s "$input") wall_s=$wall user_s=$user sys_s=$sys peak_rss_mib=$((rss / 1024))"

for budget in none "${budgets[@]}"; do
  flags=()
  [ "$budget" != none ] && flags=(--memory-budget "$budget" --temp-dir "$work")
  read -r wall user sys rss < <(measure "$cli" sort "$input" "$work/sorted.oms" "${flags[@]}")
  runs=$(grep -o '[0-9]* runs merged' "$work/out.txt" | awk '{ print $1 }' || true)
  digest=$(md5sum < "$work/sorted.oms" | cut -c1-12)
  echo "bench=memory_budget command=sort budget=$budget points=$points wall_s=$wall user_s=$user sys_s=$sys peak_rss_mib=$((rss / 1024)) sort_runs=${runs:-0} oms_md5=$digest"
  rm -f "$work/sorted.oms"
  read -r wall user sys rss < <(measure "$cli" build "$input" --json "${flags[@]}")
  runs=$(json_field sort_runs "$work/out.txt")
  echo "bench=memory_budget command=build budget=$budget points=$points wall_s=$wall user_s=$user sys_s=$sys peak_rss_mib=$((rss / 1024)) sort_runs=${runs:-0}"
done
