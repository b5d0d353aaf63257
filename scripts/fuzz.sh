#!/usr/bin/env bash
# The long fuzzing job (outside the default suite, which runs each target a few seconds with
# the standalone driver): builds the `fuzz` preset (clang, libFuzzer, ASan + UBSan) and runs
# every reader's target — PLY, LAS, LAZ, XYZ, .oms, .omh — for SECONDS each (default 600),
# two at a time, on a corpus seeded from ../shared/data (and .oms/.omh made from bunny.ply by
# the release omicron-cli, when it is built). Prints one key=value line per target; a crash
# leaves its input in build/fuzz/artifacts/ and fails the job. Turn a crash into a regression
# test by adding the input to the reader's malformed-input tests.
#   ./scripts/fuzz.sh [SECONDS] [TARGET...]     (targets: ply las laz xyz oms omh; default all)
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/common.sh
omicron_install_packages
if ! command -v clang++ >/dev/null; then # libFuzzer comes with Debian's clang
  sudo=()
  [ "$(id -u)" -ne 0 ] && sudo=(sudo)
  "${sudo[@]}" apt-get -o DPkg::Lock::Timeout=600 install -y --no-install-recommends clang
fi

seconds=${1:-600}
shift || true
targets=("$@")
[ "${#targets[@]}" -eq 0 ] && targets=(ply las laz xyz oms omh)
cmake --preset fuzz >/dev/null
cmake --build --preset fuzz --target "${targets[@]/#/fuzz_}"

shared=../shared/data
work=build/fuzz/work
rm -rf "$work"
mkdir -p "$work" build/fuzz/artifacts
seed() { # target, files...
  local target=$1
  shift
  mkdir -p "$work/corpus-$target"
  for file in "$@"; do
    [ -f "$file" ] && cp "$file" "$work/corpus-$target/" || true
  done
}
seed ply "$shared"/bunny.ply "$shared"/lion.ply "$shared"/sorvilier.ply "$shared"/autzen_trim.ply \
  fuzz/seeds-ply/*
seed las "$shared"/autzen_trim.las "$shared"/laz/simple.las "$shared"/laz/1.2-with-color.copc.las
seed laz "$shared"/laz/simple.laz "$shared"/laz/1.2-with-color.copc.laz "$shared"/laz/autzen_trim.laz \
  tests/data/laz/simple-laszip-v1.laz tests/data/laz/waveform-format4.laz \
  tests/data/laz/waveform-format5.laz
seed xyz fuzz/seeds/cloud.xyz
seed oms
seed omh
if [ -x build/release/bin/omicron-cli ] && [ -f "$shared/bunny.ply" ]; then
  build/release/bin/omicron-cli sort "$shared/bunny.ply" "$work/corpus-oms/bunny.oms" >/dev/null
  build/release/bin/omicron-cli build "$shared/bunny.ply" --depth 4 \
    --save "$work/corpus-omh/bunny.omh" >/dev/null
  build/release/bin/omicron-cli build "$shared/bunny.ply" --depth 4 \
    --save "$work/corpus-omh/bunny-v2.omh" --save-version 2 >/dev/null
fi

run() {
  local target=$1
  local log="$work/$target.log"
  local status=0
  ASAN_OPTIONS=detect_leaks=1 build/fuzz/bin/fuzz_$target "$work/corpus-$target" \
    -max_total_time="$seconds" -max_len=262144 -rss_limit_mb=3072 -timeout=20 \
    -artifact_prefix="build/fuzz/artifacts/$target-" >"$log" 2>&1 || status=$?
  local runs
  runs=$(grep -o 'Done [0-9]* runs' "$log" | grep -o '[0-9]*' || echo 0)
  local crashes
  crashes=$(ls build/fuzz/artifacts/ 2>/dev/null | grep -c "^$target-" || true)
  echo "fuzz=$target driver=libfuzzer seconds=$seconds runs=$runs crashes=$crashes exit=$status"
  return "$status"
}
failed=0
for ((i = 0; i < ${#targets[@]}; i += 2)); do
  if ((i + 1 < ${#targets[@]})); then
    run "${targets[i]}" &
    first=$!
    run "${targets[i + 1]}" || failed=1
    wait "$first" || failed=1
  else
    run "${targets[i]}" || failed=1
  fi
done
rm -rf "$work"
exit "$failed"
