#!/usr/bin/env bash
# The clusters against the truth, end to end: a held-out set of rendered
# scenes (scripts/heldout_scenes.py, a seed no default was chosen on), each
# run by `celc run` with its default options. A `celc synth` sequence holds
# labels.txt, so every window of windows.csv carries the clusters' quality
# against the true edges and the oracle: celc_ml on the window's true
# clusters, with the same lines code, gyro and seed (docs/clustering.md).
#   scripts/cluster_table.sh [OUTDIR] [--seed S] [--count N] [--kinds K] [--speed LO,HI] [--rate LO,HI]
#                            [--runs NAME] [-- extra celc run arguments]
# Defaults: OUTDIR out/cluster-table, seed 30000, 12 scenes of the kinds
# room,hand,rect,deep. Prints one row per window, then the issue's targets:
# event-weighted purity, impure clusters per window, edge completeness,
# coverage and the gap between celc_ml on the pipeline's clusters and on the
# true ones. About 1 minute per scene on 2 cores (rendering included). The
# scenes go to OUTDIR/scenes (rendered again only when their YAML changes),
# the runs to OUTDIR/NAME (--runs, default run).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
out="$root/out/cluster-table"
seed=30000
count=12
kinds="room,hand,rect,deep"
runs=run
if [ $# -gt 0 ] && [ "${1#-}" = "$1" ]; then out="$1"; shift; fi
extra=()
draw=()
while [ $# -gt 0 ]; do
  case "$1" in
    --seed) seed="$2"; shift 2 ;;
    --count) count="$2"; shift 2 ;;
    --kinds) kinds="$2"; shift 2 ;;
    --speed) draw+=(--speed "$2"); shift 2 ;;
    --rate) draw+=(--rate "$2"); shift 2 ;;
    --runs) runs="$2"; shift 2 ;;
    --) shift; extra=("$@"); break ;;
    *) echo "cluster_table.sh: unknown argument '$1'" >&2; exit 2 ;;
  esac
done
celc="${CELC_BINARY:-${CELC_BUILD_DIR:-$root/build}/celc}"
[ -x "$celc" ] || "$root/scripts/setup.sh"
mkdir -p "$out/scenes" "$out/$runs"
/usr/bin/python3 "$root/scripts/heldout_scenes.py" "$out/scenes" --count "$count" --seed "$seed" \
  --kinds "$kinds" "${draw[@]}" > "$out/scenes.txt"
for f in "$out"/scenes/*.yaml; do
  name=$(basename "$f" .yaml)
  seq="$out/scenes/$name"
  if [ ! -f "$seq/events.txt" ] || ! cmp -s "$f" "$seq/.scene.yaml"; then
    "$celc" synth "$f" -o "$seq" --force -q
    cp "$f" "$seq/.scene.yaml"
  fi
  "$celc" run "$seq" -o "$out/$runs/$name" --force -q --no-plots "${extra[@]}" > /dev/null
done
/usr/bin/python3 "$root/scripts/cluster_quality.py" "$out/$runs" --scenes "$out/scenes"
