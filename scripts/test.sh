#!/usr/bin/env bash
# The README's test command: installs what is missing, builds, runs every test.
#   scripts/test.sh            (CTest output on stdout; exit status = CTest's)
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
"$root/scripts/setup.sh"
cd "${CELC_BUILD_DIR:-$root/build}"
ctest --output-on-failure -j "${CELC_JOBS:-$(nproc)}" --timeout 300
