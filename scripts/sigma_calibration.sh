#!/usr/bin/env bash
# The calibration of sigma_deg (docs/uncertainty.md): the share of ok windows
# with phi <= 2 sigma_deg per method and setting, on simulated windows
# (`celc simulate --study sigma`) and on rendered scenes (`celc synth` of
# config/scenes/*.yaml, then `celc run`). Usage: scripts/sigma_calibration.sh [OUTDIR] [TRIALS]
set -euo pipefail
cd "$(dirname "$0")/.."
OUT=${1:-out/sigma-calibration}
TRIALS=${2:-100}
CELC=${CELC:-build/celc}
mkdir -p "$OUT"
"$CELC" simulate --study sigma --trials "$TRIALS" --threads 2 -o "$OUT/sim" --force -q
echo
echo "Rendered scenes: share of ok rows with phi <= 2 sigma_deg (ok rows with ground truth)"
echo
echo "| scene | window | method | share | ok |"
echo "|---|---|---|---|---|"
for scene in config/scenes/sample_davis346_room.yaml config/scenes/e2e_davis346_room_fast.yaml; do
  name=$(basename "$scene" .yaml)
  [ -d "$OUT/$name/seq" ] || "$CELC" synth "$scene" -o "$OUT/$name/seq" -q
  for n in 30000 50000; do
    "$CELC" run "$OUT/$name/seq" -o "$OUT/$name/run_$n" --window-events "$n" --force --no-plots -q > /dev/null
    awk -F, -v s="$name" -v n="$n" 'NR > 1 && $7 == "ok" && $15 != "" && $18 != "" {
        ok[$6]++; if ($15 <= 2 * $18 * 3.14159265 / 180) c[$6]++ }
      END { for (m in ok) printf "| %s | %s events | %s | %.2f | %d |\n", s, n, m, c[m] / ok[m], ok[m] }' \
      "$OUT/$name/run_$n/windows.csv" | sort
  done
done
