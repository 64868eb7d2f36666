#!/usr/bin/env bash
# Why the parallax window policy: the accuracy of the line methods against D,
# the translation a window's lines show (windows.csv column translation_px),
# over fixed window lengths on every scene of scripts/scene_table.sh (the
# shipped scenes and their held-out variants). Prints per scene and length the
# median D and median phi [rad], then every window bucketed by D.
#   scripts/parallax_study.sh [OUTDIR]   (default out/scenes; renders cached there)
# About 15 minutes on 2 cores after the renders (scene_table.sh makes them).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
out="${1:-$root/out/scenes}"
celc="${CELC_BINARY:-$root/build/celc}"
[ -d "$out/seq" ] || "$root/scripts/scene_table.sh" "$out" >/dev/null
mkdir -p "$out/lengths"
for seq in "$out"/seq/*/; do
  name="$(basename "$seq")"
  [ -f "$seq/events.txt" ] || continue
  for s in 0.03 0.05 0.1 0.15 0.2 0.3; do
    "$celc" run "$seq" --window-seconds "$s" -o "$out/lengths/$name@$s" --force -q --no-plots >/dev/null
  done
done
/usr/bin/python3 - "$out/lengths" <<'PY'
import csv, glob, math, os, statistics, sys
def med(x): return statistics.median(x) if x else float("nan")
rows = []
for d in sorted(glob.glob(os.path.join(sys.argv[1], "*@*"))):
    scene, length = os.path.basename(d).rsplit("@", 1)
    per_window = {}
    for r in csv.DictReader(open(os.path.join(d, "windows.csv"))):
        w = per_window.setdefault(r["window"], {"D": float(r["translation_px"] or "nan")})
        w[r["method"]] = float(r["phi"]) if r["phi"] else float("nan")
    for w in per_window.values():
        rows.append((scene, float(length), w["D"], w.get("celc_ml", math.nan), w.get("celc_opt", math.nan)))
print("| scene | window [s] | windows | median D [px] | celc_ml median phi | celc_opt median phi |")
print("|---|---|---|---|---|---|")
for key in sorted({(r[0], r[1]) for r in rows}):
    rs = [r for r in rows if (r[0], r[1]) == key]
    fin = lambda i: [r[i] for r in rs if not math.isnan(r[i])]
    print(f"| {key[0]} | {key[1]:.2f} | {len(rs)} | {med(fin(2)):.1f} | {med(fin(3)):.3f} | {med(fin(4)):.3f} |")
print()
print("| D [px] | windows | celc_ml median phi | share <= 0.1 rad | celc_opt median phi |")
print("|---|---|---|---|---|")
edges = [0, 3, 6, 10, 15, 25, 40, math.inf]
for lo, hi in zip(edges, edges[1:]):
    rs = [r for r in rows if lo <= r[2] < hi and not math.isnan(r[3])]
    if not rs: continue
    ml = [r[3] for r in rs]
    op = [r[4] for r in rs if not math.isnan(r[4])]
    print(f"| {lo}-{hi} | {len(rs)} | {med(ml):.3f} | {sum(x <= 0.1 for x in ml) / len(ml):.2f} | {med(op):.3f} |")
PY
