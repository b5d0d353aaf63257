# Shared by the benchmark scripts (source it; needs $work, a scratch folder): runs a command
# under /usr/bin/time -v with its output in $work/out.txt and $work/err.txt, and prints
# "wall_s user_s sys_s peak_kib".
# shellcheck shell=bash
measure() {
  /usr/bin/time -v -o "$work/time.txt" "$@" > "$work/out.txt" 2> "$work/err.txt"
  awk -F': ' '/Elapsed \(wall clock\)/ { n = split($2, t, ":"); wall = (n == 3) ? t[1]*3600 + t[2]*60 + t[3] : t[1]*60 + t[2] }
              /User time/ { user = $2 } /System time/ { sys = $2 }
              /Maximum resident set size/ { rss = $2 }
              END { printf "%.2f %.2f %.2f %d\n", wall, user, sys, rss }' "$work/time.txt"
}
