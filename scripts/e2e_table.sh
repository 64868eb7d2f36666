#!/usr/bin/env bash
# End-to-end accuracy of `celc run` on rendered sequences (celc synth) over a
# few settings: speed, background noise rate, contrast threshold, scene seed.
# Prints a markdown table of the median phi [rad] per method (ok windows / all
# in brackets for celc_ml) and keeps every sequence and run under OUTDIR.
#   scripts/e2e_table.sh [OUTDIR]      (default out/e2e; about 2 minutes on 2 cores)
# Base setting: config/scenes/e2e_davis346_room_fast.yaml (4 m/s, 0.1 s windows).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
out="${1:-$root/out/e2e}"
celc="${CELC_BINARY:-$root/build/celc}"
[ -x "$celc" ] || "$root/scripts/setup.sh"
base="$root/config/scenes/e2e_davis346_room_fast.yaml"
mkdir -p "$out"

# name | sed edits of the scene | window [s] | seed
settings=(
  "base 4 m/s, 0.1 s||0.1|1"
  "base, scene seed 2||0.1|2"
  "base, scene seed 3||0.1|3"
  "4 m/s, 0.05 s windows||0.05|1"
  "4 m/s, 0.15 s windows||0.15|1"
  "2 m/s, 0.2 s windows|s/v: \[3.2, -0.6, 2.4\]/v: [1.6, -0.3, 1.2]/;s/^duration: 0.41/duration: 0.81/|0.2|1"
  "noise 2 Hz/px|s/noise_rate: 0.1 /noise_rate: 2.0 /|0.1|1"
  "noise 10 Hz/px|s/noise_rate: 0.1 /noise_rate: 10.0 /|0.1|1"
  "threshold 0.15|s/contrast_on: 0.25/contrast_on: 0.15/;s/contrast_off: 0.25/contrast_off: 0.15/|0.1|1"
  "threshold 0.4|s/contrast_on: 0.25/contrast_on: 0.4/;s/contrast_off: 0.25/contrast_off: 0.4/|0.1|1"
)
methods="celc celc_opt celc_ml ce3lc npt"
printf '| setting | events | celc | celc_opt | celc_ml (ok/windows) | ce3lc | npt |\n|---|---|---|---|---|---|---|\n'
i=0
for s in "${settings[@]}"; do
  IFS='|' read -r name edits window seed <<<"$s"
  i=$((i + 1))
  dir="$out/setting$i"
  mkdir -p "$dir"
  sed -e "${edits:-s/^//}" "$base" >"$dir/scene.yaml"
  "$celc" synth "$dir/scene.yaml" -o "$dir/seq" --seed "$seed" --force -q
  "$celc" run "$dir/seq" -c "$root/config/run.yaml" --window-seconds "$window" \
    -o "$dir/run" --force -q >/dev/null
  n_events=$(wc -l <"$dir/seq/events.txt")
  row="| $name | $n_events |"
  for m in $methods; do
    # summary.md columns: method, windows, ok, with gt, mean eps, median eps, mean phi, median phi
    cell=$(awk -F'|' -v m=" $m " '$2 == m { gsub(/ /, "", $9); gsub(/ /, "", $4); gsub(/ /, "", $3);
            printf "%s (%s/%s)", $9, $4, $3 }' "$dir/run/summary.md")
    [ "$m" = celc_ml ] || cell="${cell%% (*}"
    row="$row ${cell:--} |"
  done
  echo "$row"
done
