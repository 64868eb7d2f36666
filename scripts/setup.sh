#!/usr/bin/env bash
# Installs the Debian packages celc needs (when missing; through sudo when not
# root), then configures and builds in Release into build/.
#   scripts/setup.sh [extra cmake args...]
# Environment: CELC_BUILD_DIR (default build), CELC_JOBS (default nproc),
#              CELC_WERROR=ON to treat warnings as errors (CI).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${CELC_BUILD_DIR:-$root/build}"
packages=(build-essential cmake pkg-config
  libeigen3-dev libceres-dev libopencv-dev libpcl-dev libpng-dev libcli11-dev libyaml-cpp-dev
  libspdlog-dev libfmt-dev libgtest-dev libgmock-dev libbenchmark-dev
  liblz4-dev libzstd-dev libflatbuffers-dev flatbuffers-compiler
  libbz2-dev zlib1g-dev libhdf5-dev hdf5-filter-plugin-blosc-serial
  python3 python3-matplotlib python3-numpy
  python3-dev pybind11-dev python3-pytest)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ "${#missing[@]}" -gt 0 ]; then
  echo "setup: installing ${missing[*]}" >&2
  sudo_cmd=()
  [ "$(id -u)" -ne 0 ] && sudo_cmd=(sudo)
  "${sudo_cmd[@]}" apt-get update -qq
  DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >&2
fi

cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release \
  -DCELC_WERROR="${CELC_WERROR:-OFF}" "$@" >&2
cmake --build "$build" -j "${CELC_JOBS:-$(nproc)}" >&2
