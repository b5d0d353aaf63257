# Shared by the benchmark scripts (source it from the repository root). measure: runs a command under /usr/bin/time -v
# with its output in $work/out.txt and $work/err.txt ($work: a scratch folder), and prints
# "wall_s user_s sys_s peak_kib".
# shellcheck shell=bash
measure() {
  /usr/bin/time -v -o "$work/time.txt" "$@" > "$work/out.txt" 2> "$work/err.txt"
  awk -F': ' '/Elapsed \(wall clock\)/ { n = split($2, t, ":"); wall = (n == 3) ? t[1]*3600 + t[2]*60 + t[3] : t[1]*60 + t[2] }
              /User time/ { user = $2 } /System time/ { sys = $2 }
              /Maximum resident set size/ { rss = $2 }
              END { printf "%.2f %.2f %.2f %d\n", wall, user, sys, rss }' "$work/time.txt"
}

# The median of the numbers on standard input (separated by spaces or lines).
median() {
  tr ' ' '\n' | grep -v '^$' | sort -g |
    awk '{ v[NR] = $1 } END { print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'
}

# The value of field NAME in the JSON of FILE (`-`: standard input), a number or a string
# (without its quotes); nothing when absent. Enough for `omicron-cli ... --json`'s flat fields.
# usage: json_field NAME FILE
json_field() {
  grep -o "\"$1\":\(\"[^\"]*\"\|[0-9.eE+-]*\)" "$2" | head -n 1 | cut -d: -f2- | tr -d '"' || true
}

# Two memory-heavy steps of run RUN in the order to run them: A B in odd runs, B A in even ones.
# They run back to back after a script's light steps (dd and the like): on a VM that hands freed
# memory back to its host, the first big process after a second of little memory use faults its
# memory in at several times the cost (README, "the host's slow phase"), and a step that always
# came first after the light ones paid that alone.
# usage: in_turn RUN A B
in_turn() {
  if [ $(($1 % 2)) -eq 0 ]; then echo "$3 $2"; else echo "$2 $3"; fi
}

# The number of points `omicron-cli info` reports for a cloud file ($cli: the omicron-cli binary).
points_in() {
  "$cli" info "$1" | awk '/^points:/ { print $2 }'
}

# Makes $work (a scratch folder under $BENCH_DIR, default /dev/shm, removed on exit) and tiles
# CLOUD COPIES times into one LAS file there; sets $input and $points ($cli: omicron-cli).
# usage: tile_input NAME CLOUD COPIES
tile_input() {
  work=$(mktemp -d "${BENCH_DIR:-/dev/shm}/omicron-$1-XXXXXX")
  trap 'rm -rf "$work"' EXIT
  input="$work/input.las"
  "$cli" tile "$2" "$input" --copies "$3" > /dev/null
  points=$(points_in "$input")
}

# One `omicron-cli build $input --save $work/out.omh`, after PREFIX (e.g. `taskset -c 0` or
# `env VAR=1`): prints "wall_s user_s sys_s peak_kib", or nothing (and the build's errors on
# stderr) when no .omh was written, so that a `read` of it fails the calling script.
# usage: measure_build NAME [PREFIX...]
measure_build() {
  local name=$1
  shift
  rm -f "$work/out.omh"
  local figures
  figures=$(measure "$@" "$cli" build "$input" --save "$work/out.omh")
  if [ -s "$work/out.omh" ]; then
    echo "$figures"
  else
    echo "$name: the build wrote nothing:" >&2
    cat "$work/err.txt" >&2
  fi
}

# The arguments of a benchmark on a tiled cloud: CLOUD, then --copies K, --runs N and the
# options named in EXTRA (e.g. "idle" for --idle S), each setting the variable of its name (set
# the defaults first). Sets $cloud and $cli (omicron-cli, which must be built); exits 2 on a
# usage error, 77 (skipped) when CLOUD is absent.
# usage: parse_cloud_args NAME "EXTRA" "$@"
parse_cloud_args() {
  local name=$1 allowed=" copies runs $2 "
  shift 2
  cloud=${1:?usage: bench/$name.sh CLOUD [--copies K] [--runs N] ...}
  shift
  while [ $# -gt 0 ]; do
    local option=${1#--}
    if [[ ! $option =~ ^[a-z]+$ || $allowed != *" $option "* || $# -lt 2 ]]; then
      echo "$name: unknown option or missing value: $1" >&2
      exit 2
    fi
    printf -v "$option" '%s' "$2"
    shift 2
  done
  cli=build/release/bin/omicron-cli
  [ -x "$cli" ] || { echo "$name: build first (./scripts/build.sh)" >&2; exit 1; }
  [ -f "$cloud" ] || { echo "$name: $cloud is absent" >&2; exit 77; }
}
