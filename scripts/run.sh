#!/usr/bin/env bash
# Builds, generates the built-in default cloud (our own procedural scan-like scene) once, and
# shows it. Until the GUI lands this prints omicron-cli's summary of the cloud.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/build.sh

default_cloud=build/default-cloud.ply
if [ ! -s "$default_cloud" ]; then
  ./build/release/bin/omicron-cli generate --points 3000000 --seed 1 "$default_cloud"
fi
exec ./build/release/bin/omicron-cli info "$default_cloud" "$@"
