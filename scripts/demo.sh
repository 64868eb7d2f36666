#!/usr/bin/env bash
# The README's main command: installs what is missing, builds, then runs the
# main job on the bundled sample: `celc run` on data/sample_seq (a simulated
# DAVIS346 sequence with IMU and ground truth), printing the summary table;
# then a room scene rendered by `celc synth` (4 m/s) through `celc run`, both
# with the default options (windows grown until their lines show parallax,
# windows.policy parallax); then a small `celc simulate` study (tables on
# stdout, CSV + PNG).
# Results: out/demo-run/, out/demo-e2e-run/ and out/demo-simulate/.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
"$root/scripts/setup.sh"
build="${CELC_BUILD_DIR:-$root/build}"
"$build/celc" run "$root/data/sample_seq" -o "$root/out/demo-run" --force
"$build/celc" synth "$root/config/scenes/e2e_davis346_room_fast.yaml" -o "$root/out/demo-e2e" --force -q
"$build/celc" run "$root/out/demo-e2e" -o "$root/out/demo-e2e-run" --force
"$build/celc" simulate --sweep all --trials 40 --seed 1 -c "$root/config/simulate.yaml" \
  -o "$root/out/demo-simulate" --force -q
echo "results: out/demo-run and out/demo-e2e-run (windows.csv, summary.md, config.yaml)," \
  "out/demo-simulate (CSV, PNG)" >&2
