#!/usr/bin/env bash
# celc_acc against celc_ml on the paper's default scene (5 lines of 200
# events, 2 px event and line noise, 0.5 s) with a constant acceleration:
# `celc simulate --sweep acceleration`, rho = |a| Z / (2 V^2) from 0 to 30,
# the acceleration's direction drawn per trial, fixed seed.
#   scripts/acceleration_sweep.sh [TRIALS] [OUTDIR]   (default 200 trials, out/acceleration-sweep; about 30 s)
# Prints one row per rho: the median phi [deg] of celc_ml and celc_acc over
# the trials whose status is ok, their ratio, the median solver times [ms]
# and their ratio (one thread; celc_acc's time includes celc_ml's, which it
# starts from). Times are wall-clock and follow the machine's load.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
trials="${1:-200}"
out="${2:-$root/out/acceleration-sweep}"
celc="${CELC_BINARY:-${CELC_BUILD_DIR:-$root/build}/celc}"
[ -x "$celc" ] || "$root/scripts/setup.sh"
mkdir -p "$out"
"$celc" simulate --sweep acceleration --methods celc_ml,celc_acc --trials "$trials" --seed 1 --threads 1 \
  -o "$out" --force -q --no-plots > "$out/simulate.txt"
/usr/bin/python3 - "$out/simulate.txt" "$out/acceleration.csv" <<'PY'
import csv, math, sys
text, table = open(sys.argv[1]).read().splitlines(), sys.argv[2]
ok = {}
for r in csv.DictReader(open(table)):
    ok[(float(r["level"]), r["method"])] = (int(r["n_ok"]), int(r["trials"]))
start = next(i for i, l in enumerate(text) if l.startswith("Sweep acceleration: median"))
rows = [l for l in text[start + 1:] if l.startswith("| ") and not l.startswith("| rho")]
print("| rho | celc_ml phi [deg] | celc_acc phi [deg] | celc_ml / celc_acc | celc_ml [ms] | celc_acc [ms] | time ratio | ok (celc_ml / celc_acc) |")
print("|---|---|---|---|---|---|---|---|")
for l in rows:
    cells = [c.strip() for c in l.strip("|").split("|")]
    rho = float(cells[0])
    (pm, tm), (pa, ta) = [tuple(float(x) for x in c.split(" / ")) for c in cells[1:3]]
    n_ml, n = ok[(rho, "celc_ml")]
    n_acc, _ = ok[(rho, "celc_acc")]
    print(f"| {rho:g} | {pm:.2f} | {pa:.2f} | {pm / pa:.2f} | {tm:.1f} | {ta:.1f} | {ta / tm:.2f} | {n_ml} / {n_acc} of {n} |")
PY
