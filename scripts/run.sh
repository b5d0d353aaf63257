#!/usr/bin/env bash
# Builds and starts the desktop application on the user's display. Without arguments it shows
# the built-in generated scene (our own procedural scan-like cloud, generated in memory while
# the hierarchy builds); any arguments go to omicron, e.g. ./scripts/run.sh ../shared/data/bunny.ply
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/build.sh

if [ -z "${DISPLAY:-}" ] && [ -z "${WAYLAND_DISPLAY:-}" ]; then
  echo "omicron: no display (DISPLAY/WAYLAND_DISPLAY unset); for a headless look use" >&2
  echo "  xvfb-run -a -s '-screen 0 1600x1000x24' ./build/release/bin/omicron" >&2
  exit 1
fi
exec ./build/release/bin/omicron "$@"
