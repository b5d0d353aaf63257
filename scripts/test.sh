#!/usr/bin/env bash
# Builds everything (programs, tests, benchmarks) and runs the whole suite under Xvfb, so GUI
# and GL tests get a real X server with Mesa's OpenGL.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/build.sh
cmake --build --preset release

jobs=$(nproc)
cd build/release
exec xvfb-run -a -s '-screen 0 1280x800x24' ctest --output-on-failure -j "$jobs" "$@"
