#!/usr/bin/env bash
# End-to-end throughput of `celc run` on a synthetic DAVIS346 chessboard
# sequence (~0.6 M events/s): with the default settings (windows grown for
# parallax) and with 1,000,000-event windows; prints the events/s and the
# share of time per stage (from summary.md).
#   scripts/bench_pipeline.sh [threads (default 2)]
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${CELC_BUILD_DIR:-$root/build}"
threads="${1:-2}"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
# ~0.6 M events per simulated second: 5 s gives 3 windows of 1 M events.
"$build/celc" synth "$root/config/scenes/davis346_chessboard.yaml" -o "$work/seq" --duration 5 -q
for policy in default events; do
  args=()
  [ "$policy" = events ] && args=(--window-events 1000000)
  "$build/celc" run "$work/seq" -o "$work/out-$policy" "${args[@]}" --threads "$threads" --no-plots -q > /dev/null
  echo "celc run, ${args[*]:-default windows}, $threads threads:"
  grep -E "windows processed|time per stage" "$work/out-$policy/summary.md"
  grep -E "^\| (celc|celc_opt|celc_ml|ce3lc) " "$work/out-$policy/summary.md" | cut -d'|' -f2,3,4,8,9,12
done
