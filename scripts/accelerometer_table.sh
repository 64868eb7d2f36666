#!/usr/bin/env bash
# Whether the accelerometer helps celc_acc: every scene of scripts/scene_table.sh
# rendered with an IMU that starts with a still second and a MEMS
# accelerometer's noise and bias (scripts/imu_still_scene.py), then run by
# `celc run` with its defaults (motion.use_accelerometer: true) and again
# without the accelerometer. Prints both scene tables and, per window where
# either run's celc_acc differs, both answers.
#   scripts/accelerometer_table.sh [OUTDIR]      (default out/accelerometer; about 15 minutes)
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
out="${1:-$root/out/accelerometer}"
export CELC_SCENE_FILTER="/usr/bin/python3 $root/scripts/imu_still_scene.py"
echo "## With the accelerometer (the default)"
echo
"$root/scripts/scene_table.sh" "$out/with"
mkdir -p "$out/without"
rm -rf "$out/without/seq"
cp -r "$out/with/seq" "$out/without/seq"
echo
echo "## Without (--set motion.use_accelerometer=false)"
echo
"$root/scripts/scene_table.sh" "$out/without" -- --set motion.use_accelerometer=false
echo
/usr/bin/python3 - "$out" <<'PY'
import csv, os, sys
out = sys.argv[1]
print("| scene | window | phi with [rad] | model with | phi without [rad] | model without |")
print("|---|---|---|---|---|---|")
changed = 0
for name in sorted(os.listdir(os.path.join(out, "with", "run"))):
    paths = [os.path.join(out, side, "run", name, "windows.csv") for side in ("with", "without")]
    if not all(os.path.exists(p) for p in paths):
        continue
    rows = [{r["window"]: r for r in csv.DictReader(open(p)) if r["method"] == "celc_acc"} for p in paths]
    for w in sorted(rows[0], key=int):
        a, b = rows[0][w], rows[1].get(w)
        if b is None or (a["phi"], a["model"]) == (b["phi"], b["model"]):
            continue
        changed += 1
        print(f"| {name} | {w} | {a['phi'] or '-'} | {a['model'] or a['status']} | {b['phi'] or '-'} | "
              f"{b['model'] or b['status']} |")
print(f"\n{changed} windows differ.")
PY
