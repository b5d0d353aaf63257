# Shared by build.sh, run.sh and test.sh: the Debian packages the project needs.
# shellcheck shell=bash
OMICRON_PACKAGES=(
  cmake ninja-build g++ pkg-config
  qt6-base-dev libqt6opengl6-dev qt6-charts-dev libglm-dev libtbb-dev libgtest-dev libxxhash-dev
  xvfb xauth libgl1-mesa-dri mesa-utils fonts-dejavu-core
  dpkg-dev file
  chromium
)

omicron_missing_packages() {
  local package
  for package in "${OMICRON_PACKAGES[@]}"; do
    if ! dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed"; then
      printf '%s\n' "$package"
    fi
  done
  # The Potree client test runs on node and npm: Debian's, unless a node is already there (a
  # NodeSource nodejs brings its own npm, which Debian's npm package would conflict with).
  if ! command -v node >/dev/null 2>&1; then
    printf '%s\n' nodejs
  fi
  if ! command -v npm >/dev/null 2>&1; then
    printf '%s\n' npm
  fi
}

omicron_install_packages() {
  local missing
  mapfile -t missing < <(omicron_missing_packages)
  if [ "${#missing[@]}" -eq 0 ]; then
    return 0
  fi
  echo "omicron: installing Debian packages: ${missing[*]}" >&2
  local sudo=()
  if [ "$(id -u)" -ne 0 ]; then
    sudo=(sudo)
  fi
  export DEBIAN_FRONTEND=noninteractive
  "${sudo[@]}" apt-get -o DPkg::Lock::Timeout=600 update -q
  "${sudo[@]}" apt-get -o DPkg::Lock::Timeout=600 install -y --no-install-recommends "${missing[@]}"
}

# The npm packages of the Potree client test (tests/web: potree-core, three, playwright-core),
# exactly as package-lock.json pins them; again only when the lock file changed. Without the
# registry the test skips with a message rather than the build failing.
omicron_install_web_test_packages() {
  local web=tests/web
  local stamp="$web/node_modules/.omicron-lock-stamp"
  if [ -f "$stamp" ] && cmp -s "$web/package-lock.json" "$stamp"; then
    return 0
  fi
  if ! command -v npm >/dev/null 2>&1; then
    echo "omicron: npm is missing; the Potree client test will be skipped" >&2
    return 0
  fi
  echo "omicron: installing the Potree client test's npm packages (npm ci in $web)" >&2
  if (cd "$web" && npm ci --no-audit --no-fund --loglevel=error >&2); then
    cp "$web/package-lock.json" "$stamp"
  else
    echo "omicron: npm ci failed; the Potree client test will be skipped" >&2
  fi
}
