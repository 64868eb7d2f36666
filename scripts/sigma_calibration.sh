#!/usr/bin/env bash
# The calibration of sigma_deg (docs/accuracy.md): the share of ok windows
# with phi <= 2 sigma_deg per method and setting, on simulated windows
# (`celc simulate --study sigma`) and on rendered scenes: the shipped scenes
# (config/scenes/*.yaml) and 16 held-out variants (scripts/heldout_scenes.py),
# rendered once with `celc synth` (cached in OUTDIR/scenes), run with the
# default options, with and without solver.uncertainty.agreement.
#   scripts/sigma_calibration.sh [OUTDIR] [TRIALS]
# About 5 minutes on 2 cores (rendering included).
set -euo pipefail
cd "$(dirname "$0")/.."
OUT=${1:-out/sigma-calibration}
TRIALS=${2:-100}
CELC=${CELC:-build/celc}
PY=/usr/bin/python3
mkdir -p "$OUT/scenes"
"$CELC" simulate --study sigma --trials "$TRIALS" --threads 2 -o "$OUT/sim" --force -q

"$PY" scripts/heldout_scenes.py "$OUT/scenes" --count 16 > /dev/null
cp config/scenes/*.yaml "$OUT/scenes/"
for f in "$OUT"/scenes/*.yaml; do
  seq="${f%.yaml}"
  if [ ! -f "$seq/events.txt" ] || ! cmp -s "$f" "$seq/.scene.yaml"; then
    "$CELC" synth "$f" -o "$seq" --force -q
    cp "$f" "$seq/.scene.yaml"
  fi
done
for agreement in true false; do
  for f in "$OUT"/scenes/*.yaml; do
    name=$(basename "$f" .yaml)
    "$CELC" run "${f%.yaml}" -o "$OUT/run-$agreement/$name" --force --no-plots -q \
      --set solver.uncertainty.agreement=$agreement > /dev/null
  done
done
echo
echo "Rendered scenes ($(ls "$OUT"/scenes/*.yaml | wc -l)), default options: share of ok rows with phi <= 2 sigma_deg;"
echo "ok rows; rows with sigma_deg < 5 deg and how many of them have phi <= 0.1 rad"
echo
echo "| method | agreement | share | ok | sigma < 5 deg | of them phi <= 0.1 rad |"
echo "|---|---|---|---|---|---|"
for agreement in true false; do
  cat "$OUT"/run-$agreement/*/windows.csv | awk -F, -v a=$agreement '
    $1 != "window" && $7 == "ok" && $15 != "" && $18 != "" {
      ok[$6]++; if ($15 <= 2 * $18 * 3.14159265 / 180) c[$6]++
      if ($18 < 5) { k[$6]++; if ($15 <= 0.1) g[$6]++ } }
    END { n = split("celc celc_opt celc_ml ce3lc npt", m, " ")
          for (i = 1; i <= n; i++) if (ok[m[i]])
            printf "| %s | %s | %.2f | %d | %d | %d |\n", m[i], a, c[m[i]] / ok[m[i]], ok[m[i]], k[m[i]], g[m[i]] }'
done
