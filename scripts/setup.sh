#!/usr/bin/env bash
# Installs adse's build and run dependencies from Debian 12 packages.
# Idempotent: installs only what is missing; does nothing when all is there.
#   scripts/setup.sh          what building and testing need
#   scripts/setup.sh --fuzz   also clang and its sanitizer runtimes (fuzz.sh)
set -euo pipefail

PACKAGES=(
  cmake g++ make ccache pkg-config git clang-format
  libyaml-cpp-dev libeigen3-dev libmuparser-dev libcli11-dev libfmt-dev
  libspdlog-dev nlohmann-json3-dev libssl-dev libcurl4-openssl-dev libcpp-httplib-dev
  sumo sumo-tools
  libpcl-dev libopencv-dev libceres-dev libhdf5-dev libpagmo-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  python3-h5py python3-pandas python3-yaml bc
  slurm-wlm munge
)
if [ "${1:-}" = "--fuzz" ]; then
  PACKAGES+=(clang-14 libclang-rt-14-dev)
fi

missing=()
for pkg in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$pkg")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#PACKAGES[@]} packages present"
  exit 0
fi

echo "setup: installing ${#missing[@]} missing packages: ${missing[*]}"
SUDO=""
if [ "$(id -u)" -ne 0 ]; then
  if command -v sudo >/dev/null 2>&1; then
    SUDO="sudo"
  else
    echo "setup: not root and no sudo; as root run:" >&2
    echo "  apt-get update && apt-get install -y --no-install-recommends ${missing[*]}" >&2
    exit 1
  fi
fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -q
$SUDO apt-get install -y -q --no-install-recommends "${missing[@]}"
echo "setup: done"
