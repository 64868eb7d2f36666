#!/usr/bin/env bash
# The calibration of sigma_deg (docs/accuracy.md): per method and per bin of
# the window's parallax D, the share of ok windows with phi <= 2 sigma_deg,
# how sharp sigma_deg is, and which rule raised it (scripts/sigma_bins.py).
#   1. simulated windows: `celc simulate --study sigma` (its own table, then
#      every ok trial binned by D);
#   2. rendered scenes with exact inputs: the shipped scenes
#      (config/scenes/*.yaml) and 16 held-out variants (scripts/heldout_scenes.py,
#      seed 2026), default `celc run`;
#   3. rendered scenes with a real sensor's input errors: 40 held-out variants
#      (seed 3030, --input-errors: gyro bias, scale, IMU rotation, principal
#      point and focal length drawn at the budget's 1-sigma sizes;
#      scripts/apply_input_errors.py), run with the default options, then
#      and without the agreement rule.
# Renders are cached in OUTDIR/scenes and OUTDIR/scenes_errors. Writes
# OUTDIR/sim.md (the simulated study's own table), OUTDIR/compact.md (one
# row per set and method), OUTDIR/bins.md (per D bin) and
# OUTDIR/reliability_*.png (phi against sigma_deg), and prints the three.
#   scripts/sigma_calibration.sh [OUTDIR] [TRIALS]
# About 12 minutes on 2 cores (rendering included).
set -euo pipefail
cd "$(dirname "$0")/.."
OUT=${1:-out/sigma-calibration}
TRIALS=${2:-100}
CELC=${CELC:-build/celc}
PY=/usr/bin/python3
mkdir -p "$OUT/scenes" "$OUT/scenes_errors"

# render DIR: every DIR/*.yaml once (again when the yaml changed); a scene with
# DIR/NAME.errors.json gets the user's calibration errors applied after rendering.
render() {
  for f in "$1"/*.yaml; do
    seq="${f%.yaml}"
    if [ ! -f "$seq/events.txt" ] || ! cmp -s "$f" "$seq/.scene.yaml"; then
      "$CELC" synth "$f" -o "$seq" --force -q
      [ ! -f "$seq.errors.json" ] || "$PY" scripts/apply_input_errors.py "$seq" "$seq.errors.json"
      cp "$f" "$seq/.scene.yaml"
    fi
  done
}
# runs DIR RUNDIR [--set ...]: default `celc run` on every scene of DIR.
runs() {
  local dir=$1 rundir=$2
  shift 2
  for f in "$dir"/*.yaml; do
    seq="${f%.yaml}"
    calib=()
    [ ! -f "$seq/calib_user.yaml" ] || calib=(--calib "$seq/calib_user.yaml")
    "$CELC" run "$seq" "${calib[@]}" -o "$rundir/$(basename "$seq")" --force --no-plots -q "$@" > /dev/null
  done
}

"$CELC" simulate --study sigma --trials "$TRIALS" --threads 2 -o "$OUT/sim" --force -q > "$OUT/sim.md"

"$PY" scripts/heldout_scenes.py "$OUT/scenes" --count 16 > /dev/null
cp config/scenes/*.yaml "$OUT/scenes/"
render "$OUT/scenes"
runs "$OUT/scenes" "$OUT/run-exact"

"$PY" scripts/heldout_scenes.py "$OUT/scenes_errors" --count 40 --seed 3030 --input-errors > /dev/null
render "$OUT/scenes_errors"
runs "$OUT/scenes_errors" "$OUT/run-errors"
runs "$OUT/scenes_errors" "$OUT/run-errors-noagree" --set solver.uncertainty.agreement=false

# The sets: label, windows.csv files, title.
sets=("simulated|$OUT/sim/sigma_trials.csv|celc simulate --study sigma, every ok trial"
      "rendered, exact inputs|$OUT/run-exact/*/windows.csv|rendered scenes with exact inputs ($(ls "$OUT"/scenes/*.yaml | wc -l)), default options"
      "rendered, input errors|$OUT/run-errors/*/windows.csv|rendered scenes with input errors (40), default options"
      "input errors, no agreement|$OUT/run-errors-noagree/*/windows.csv|rendered scenes with input errors (40), without the agreement rule")
header=--header
: > "$OUT/compact.md"
: > "$OUT/bins.md"
for entry in "${sets[@]}"; do
  IFS='|' read -r label files title <<< "$entry"
  # shellcheck disable=SC2086  # the glob in $files expands here
  "$PY" scripts/sigma_bins.py --compact "$label" $header $files >> "$OUT/compact.md"
  header=
  { echo; echo "sigma_deg by D, $title:"; echo; "$PY" scripts/sigma_bins.py $files; } >> "$OUT/bins.md"
  "$PY" scripts/sigma_bins.py --plot "$OUT/reliability_${label//[ ,]/_}.png" --title "$title" $files > /dev/null
done
cat "$OUT/sim.md"
echo
echo "Coverage of sigma_deg (share of ok windows with phi <= 2 sigma_deg; ok windows) by D:"
echo
cat "$OUT/compact.md"
cat "$OUT/bins.md"
