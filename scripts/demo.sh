#!/usr/bin/env bash
# The README's main command: installs what is missing, builds, then runs the
# main job on the bundled sample: `celc run` on data/sample_seq (a simulated
# DAVIS346 sequence with IMU and ground truth), printing the summary table;
# then a small `celc simulate` study (tables on stdout, CSV + PNG plots).
# Results: out/demo-run/ and out/demo-simulate/.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
"$root/scripts/setup.sh"
build="${CELC_BUILD_DIR:-$root/build}"
"$build/celc" run "$root/data/sample_seq" -c "$root/config/run.yaml" --window-events 50000 \
  -o "$root/out/demo-run" --force
"$build/celc" simulate --sweep all --trials 40 --seed 1 -c "$root/config/simulate.yaml" \
  -o "$root/out/demo-simulate" --force -q
echo "results: out/demo-run (windows.csv, summary.md, config.yaml), out/demo-simulate (CSV, PNG)" >&2
