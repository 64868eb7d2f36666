#!/usr/bin/env bash
# The paper's experiments with celc (Peng et al., BMVC 2021, Sec. 5).
#   scripts/reproduce_paper.sh [--trials N] [--seed S] [--threads T] [-o OUTDIR] [--data DATA_ROOT]
# 1. The simulation study (Sec. 5.1): every sweep of `celc simulate`, N trials
#    per level (default 500, the paper's count; 50 gives a quick look in about
#    10 s), seed S (default 1). Writes OUTDIR/simulation/<sweep>.csv and .png,
#    the figures under the paper's figure numbers (OUTDIR/fig3_<sweep>.png for
#    the noise sweeps, OUTDIR/fig4_<sweep>.png for speed, time interval and
#    number of lines), and OUTDIR/paper_table.md: per sweep and level the mean
#    eps (unit-vector distance) and phi [rad] of the paper's three methods
#    (CELC, CELC+opt, CE3LC) beside celc_ml; the tables `celc simulate` prints
#    go to OUTDIR/simulation_tables.md.
# 2. The real-data tables (Sec. 5.2), when DATA_ROOT holds UZH-FPV
#    indoor_45_9 (DATA_ROOT/indoor_45_9_davis with calib.yaml filled in from
#    the dataset's calibration, see config/uzh_fpv_davis_calib.yaml): a batch
#    run and `celc table --methods celc,celc_opt,ce3lc`, the paper's columns.
#    The paper's AGV sequences are not public.
# OUTDIR defaults to ${TMPDIR:-/tmp}/celc-paper, outside the source tree.
# Uses build/celc (CELC_BUILD_DIR) as it is when it exists (an incremental
# `cmake --build`, a no-op when current); installs and builds only when it
# does not (scripts/setup.sh).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
trials=500
seed=1
threads=0
out="${TMPDIR:-/tmp}/celc-paper"
data=""
usage() { sed -n '2,3p' "$0" >&2; exit 2; }
while [ $# -gt 0 ]; do
  case "$1" in
    --trials) trials="${2:?--trials needs a count}"; shift 2 ;;
    --seed) seed="${2:?--seed needs a value}"; shift 2 ;;
    --threads) threads="${2:?--threads needs a count}"; shift 2 ;;
    -o) out="${2:?-o needs a folder}"; shift 2 ;;
    --data) data="${2:?--data needs a folder}"; shift 2 ;;
    -h|--help) usage ;;
    *) echo "reproduce_paper.sh: unknown argument '$1'" >&2; usage ;;
  esac
done
case "$trials" in ''|*[!0-9]*|0) echo "reproduce_paper.sh: --trials must be a positive integer, got '$trials'" >&2; exit 2 ;; esac

build="${CELC_BUILD_DIR:-$root/build}"
if [ -x "$build/celc" ] && [ -f "$build/CMakeCache.txt" ]; then
  cmake --build "$build" --target celc -j "${CELC_JOBS:-$(nproc)}" >&2
else
  "$root/scripts/setup.sh"
fi
celc="$build/celc"
mkdir -p "$out"

"$celc" simulate --sweep all --trials "$trials" --seed "$seed" --threads "$threads" \
  -c "$root/config/simulate.yaml" -o "$out/simulation" --force -q > "$out/simulation_tables.md"
for s in event_noise line_noise omega_noise; do
  [ -f "$out/simulation/$s.png" ] && cp "$out/simulation/$s.png" "$out/fig3_$s.png"
done
for s in speed interval lines; do
  [ -f "$out/simulation/$s.png" ] && cp "$out/simulation/$s.png" "$out/fig4_$s.png"
done
/usr/bin/python3 "$root/scripts/paper_table.py" "$out/simulation" \
  "scripts/reproduce_paper.sh --trials $trials --seed $seed" > "$out/paper_table.md"
echo "wrote $out/paper_table.md and $out/fig3_*.png, $out/fig4_*.png" >&2

if [ -n "$data" ]; then
  if [ ! -d "$data/indoor_45_9_davis" ]; then
    echo "reproduce_paper.sh: $data/indoor_45_9_davis: no such folder (see config/uzh_fpv_davis.yaml)" >&2
    exit 1
  fi
  cat > "$out/batch.yaml" <<YAML
config: $root/config/uzh_fpv_davis.yaml
sequences:
  - label: indoor_45_9
    path: $data/indoor_45_9_davis
YAML
  "$celc" batch "$out/batch.yaml" -o "$out/real" --force
  "$celc" table "$out/real" --methods celc,celc_opt,ce3lc -o "$out/real_table"
fi
