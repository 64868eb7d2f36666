#!/usr/bin/env bash
# Reproduces the paper's results with celc.
#   scripts/reproduce_paper.sh [DATA_ROOT] [OUTDIR]
# 1. The simulation study (Sec. 5.1, Figs. 3 and 4): every sweep, 500 trials
#    per level, CSV + PNG in OUTDIR/simulation.
# 2. The real-data tables (Tables 1 and 2), when DATA_ROOT holds the
#    sequences: UZH-FPV indoor_45_9 (DATA_ROOT/indoor_45_9_davis with
#    DATA_ROOT/indoor_45_9_davis/calib.yaml filled in from the dataset's
#    calibration, see config/uzh_fpv_davis_calib.yaml). The paper's AGV
#    sequences are not public and cannot be reproduced.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
data="${1:-}"
out="${2:-$root/out/paper}"
"$root/scripts/setup.sh"
celc="${CELC_BUILD_DIR:-$root/build}/celc"
"$celc" simulate --sweep all --trials 500 --seed 1 -c "$root/config/simulate.yaml" \
  -o "$out/simulation" --force
if [ -n "$data" ] && [ -d "$data/indoor_45_9_davis" ]; then
  cat > "$out/batch.yaml" <<YAML
config: $root/config/uzh_fpv_davis.yaml
sequences:
  - label: indoor_45_9
    path: $data/indoor_45_9_davis
YAML
  "$celc" batch "$out/batch.yaml" -o "$out/real" --force
else
  echo "no DATA_ROOT/indoor_45_9_davis: real-data tables skipped (see config/uzh_fpv_davis.yaml)" >&2
fi
