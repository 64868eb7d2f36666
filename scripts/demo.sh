#!/usr/bin/env bash
# The README's main command: installs what is missing, builds, then runs the
# main job on a bundled default: a small `celc simulate` study (all sweeps,
# 40 trials per level) that prints its tables and writes CSVs and PNG plots
# into out/demo-simulate/.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
"$root/scripts/setup.sh"
build="${CELC_BUILD_DIR:-$root/build}"
out="$root/out/demo-simulate"
"$build/celc" simulate --sweep all --trials 40 --seed 1 -c "$root/config/simulate.yaml" \
  -o "$out" --force
echo "results: $out (CSV per sweep, config.yaml, PNG plots)" >&2
