#!/usr/bin/env bash
# The AddressSanitizer + LeakSanitizer job (outside the default suite: an instrumented build
# of the core, the viewer and the application takes a long time on CI). Builds the `asan`
# preset (ASan + UBSan, invariant checkers on) for the whole core suite (omicron_core_tests:
# readers, sorter, builder, saves and loads, each with its threads), the tests of cancelling
# and closing while a
# build runs, and runs them under Xvfb with leak detection: tst_builderservice (cancel, also
# during a file's bounds pre-pass; destruction mid-build), tst_mainwindowGL (close mid-build,
# open, rebuild, save, errors), the hierarchy tree's tests, which read a hierarchy while a
# builder grows it (tst_hierarchymodel, tst_cutpanel), and the viewer's GL tests (node packing
# in parallel, the compute rasterizer's tables; tst_cloudview_gl, tst_computepoints_gl). Any
# leak or memory error fails the job;
# the suppressions in scripts/lsan.supp cover third-party libraries only.
# Extra arguments replace the default test list, e.g. ./scripts/asan.sh tst_builderservice.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/common.sh
omicron_install_packages

tests=("$@")
[ "${#tests[@]}" -eq 0 ] && tests=(omicron_core_tests tst_builderservice tst_mainwindowGL
  tst_hierarchymodel tst_cutpanel tst_cloudview_gl tst_computepoints_gl)

cmake --preset asan >/dev/null
cmake --build --preset asan --target "${tests[@]}"

root=$(pwd)
asan_runtime=$(g++ -print-file-name=libasan.so)
# libGL dlcloses Mesa's driver when the display closes; the driver's state is then only
# referenced from an unmapped module and LSan reports it without a name. Preloading the
# driver keeps it mapped, so what it still holds at exit stays reachable (the runtime must
# come first in the preload list).
preload="$asan_runtime"
for driver in /usr/lib/x86_64-linux-gnu/dri/swrast_dri.so /usr/lib/*/dri/swrast_dri.so; do
  if [ -f "$driver" ]; then
    preload="$preload $driver"
    break
  fi
done

export ASAN_OPTIONS="detect_leaks=1:abort_on_error=0:halt_on_error=1"
export LSAN_OPTIONS="suppressions=$root/scripts/lsan.supp:print_suppressions=1"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
status=0
for test in "${tests[@]}"; do
  echo "=== $test (ASan + LSan + UBSan)"
  if ! xvfb-run -a -s '-screen 0 1280x800x24' env LD_PRELOAD="$preload" "build/asan/bin/$test"; then
    echo "asan.sh: $test failed (test failure, memory error or leak: see above)" >&2
    status=1
  fi
done
exit "$status"
