# Shared by build.sh, run.sh and test.sh: the Debian packages the project needs.
# shellcheck shell=bash
OMICRON_PACKAGES=(
  cmake ninja-build g++ pkg-config
  qt6-base-dev libqt6opengl6-dev qt6-charts-dev libglm-dev libtbb-dev libgtest-dev libxxhash-dev
  xvfb xauth libgl1-mesa-dri mesa-utils fonts-dejavu-core
  dpkg-dev file
)

omicron_missing_packages() {
  local package
  for package in "${OMICRON_PACKAGES[@]}"; do
    if ! dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed"; then
      printf '%s\n' "$package"
    fi
  done
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
