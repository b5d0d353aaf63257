#!/usr/bin/env bash
# The ThreadSanitizer job (outside the default suite: it takes several minutes). Debian's
# libtbb is not TSan-instrumented, so this builds oneTBB from Debian's own source package with
# -DTBB_SANITIZE=thread into build/tbb-tsan, builds the `tsan` preset against it and runs the
# concurrency-heavy tests (sorter, radix sort, .oms streaming, cut and builder with a reader
# thread, LAZ chunks decoded in parallel, LAS and PLY blocks read ahead, LAS runs parsed in
# slices, the PLY bounds pre-pass on every core, text parsed and formatted on every core).
# Extra arguments replace the default test filter, e.g. ./scripts/tsan.sh '*Builder*'.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/common.sh
omicron_install_packages

root=$(pwd)
tbb_prefix="$root/build/tbb-tsan"
if [ ! -f "$tbb_prefix/lib/cmake/TBB/TBBConfig.cmake" ]; then
  sources=/etc/apt/sources.list.d/omicron-deb-src.sources
  if ! apt-get source --print-uris onetbb >/dev/null 2>&1; then
    sudo=()
    [ "$(id -u)" -ne 0 ] && sudo=(sudo)
    printf 'Types: deb-src\nURIs: http://deb.debian.org/debian\nSuites: bookworm\nComponents: main\nSigned-By: /usr/share/keyrings/debian-archive-keyring.gpg\n' |
      "${sudo[@]}" tee "$sources" >/dev/null
    "${sudo[@]}" apt-get -o DPkg::Lock::Timeout=600 update -q
  fi
  work="$root/build/tbb-tsan-src"
  rm -rf "$work" && mkdir -p "$work"
  (cd "$work" && apt-get source -q --download-only onetbb && tar xf onetbb_*.orig.tar.*)
  source_dir=$(find "$work" -maxdepth 1 -type d -name 'oneTBB-*' | head -n 1)
  # TBB's own -Werror trips GCC 12's "atomic_thread_fence is not supported with TSan" note.
  cmake -S "$source_dir" -B "$work/build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DTBB_SANITIZE=thread -DTBB_STRICT=OFF -DTBB_TEST=OFF -DTBB_EXAMPLES=OFF \
    -DTBBMALLOC_BUILD=OFF -DCMAKE_CXX_FLAGS="-Wno-tsan" -DCMAKE_INSTALL_PREFIX="$tbb_prefix"
  cmake --build "$work/build" -j "$(nproc)"
  cmake --install "$work/build"
fi

cmake --preset tsan -DTBB_DIR="$tbb_prefix/lib/cmake/TBB" >/dev/null
cmake --build build/tsan --target omicron_core_tests
filter=${1:-'*Builder*:*Sorter*:*Radix*:*Oms*:*ObliqueCut*:*Front*:*Packed*:*ChunkedArena*:*LeafRuns*:*ExternalSort*:*Budgeted*:*PrePass*:*OmhPaged*:*ResidentPages*:*OverlappedBatchConsumer*:*OmhWriter*:*OmhSafeSave*:*UniformColumns*:*BackgroundJob*:*ResidentSetGovernor*:*LazDecoder*:*LasReaderTest*:*PlyReader*:*ParallelRecordScan*:*TextBlocks*:*Xyz*:*ParallelTextWriter*'}
# halt_on_error: the first race fails the job.
TSAN_OPTIONS="halt_on_error=1 second_deadlock_stack=1" \
  LD_LIBRARY_PATH="$tbb_prefix/lib" ./build/tsan/bin/omicron_core_tests --gtest_filter="$filter"
