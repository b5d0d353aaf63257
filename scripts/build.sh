#!/usr/bin/env bash
# Installs what a fresh Debian 12 machine lacks (Debian packages, and the npm packages of the
# Potree client test in tests/web), then configures and builds Release into build/release
# (programs in build/release/bin). Quick when everything is already there.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/common.sh

omicron_install_packages
omicron_install_web_test_packages
cmake --preset release >/dev/null
cmake --build --preset release --target apps "$@"
