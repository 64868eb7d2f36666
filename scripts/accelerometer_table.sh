#!/usr/bin/env bash
# Whether the accelerometer helps celc_acc: every scene of scripts/scene_table.sh
# rendered with an IMU that starts with a still second and a MEMS
# accelerometer's noise and bias (scripts/imu_still_scene.py), run by
# `celc run` with its defaults (motion.use_accelerometer: true) and again
# without the accelerometer, on the same renders. Prints two tables: over
# every window, celc_ml and celc_acc with and without the accelerometer (the
# columns of scene_table.sh's last table); then every window whose celc_acc
# answer differs between the two runs.
#   scripts/accelerometer_table.sh [OUTDIR]      (default out/accelerometer; about 15 minutes)
# OUTDIR/with.md and OUTDIR/without.md keep both scene tables.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
out="${1:-$root/out/accelerometer}"
mkdir -p "$out/without"
export CELC_SCENE_FILTER="/usr/bin/python3 $root/scripts/imu_still_scene.py"
"$root/scripts/scene_table.sh" "$out/with" >"$out/with.md"
rm -rf "$out/without/seq"
cp -r "$out/with/seq" "$out/without/seq"
"$root/scripts/scene_table.sh" "$out/without" -- --set motion.use_accelerometer=false >"$out/without.md"
/usr/bin/python3 - "$out" <<'PY'
import csv, os, sys
out = sys.argv[1]


def last_table_rows(path):
    """The method rows of scene_table.sh's last table (over every window)."""
    rows = [l for l in open(path).read().splitlines() if l.startswith("| ")]
    header = max(i for i, l in enumerate(rows) if l.startswith("| method |"))
    return rows[header], {r.split("|")[1].strip(): r for r in rows[header + 1:]}


header, with_rows = last_table_rows(os.path.join(out, "with.md"))
_, without_rows = last_table_rows(os.path.join(out, "without.md"))
print("Over every window of every scene (scene_table.sh's columns):")
print("| run " + header)
print("|---" * (header.count("|")) + "|")
print("| with the accelerometer " + with_rows["celc_ml"])
print("| with the accelerometer " + with_rows["celc_acc"])
print("| without " + without_rows["celc_acc"])
print()
print("The windows whose celc_acc answer differs:")
print("| scene | window | phi with [rad] | model with | phi without [rad] | model without |")
print("|---|---|---|---|---|---|")
for name in sorted(os.listdir(os.path.join(out, "with", "run"))):
    paths = [os.path.join(out, side, "run", name, "windows.csv") for side in ("with", "without")]
    if not all(os.path.exists(p) for p in paths):
        continue
    rows = [{r["window"]: r for r in csv.DictReader(open(p)) if r["method"] == "celc_acc"} for p in paths]
    for w in sorted(rows[0], key=int):
        a, b = rows[0][w], rows[1].get(w)
        if b is None or (a["phi"], a["model"]) == (b["phi"], b["model"]):
            continue
        phi = lambda r: "%.3f" % float(r["phi"]) if r["phi"] else "-"
        print(f"| {name} | {w} | {phi(a)} | {a['model'] or a['status']} | {phi(b)} | {b['model'] or b['status']} |")
PY
