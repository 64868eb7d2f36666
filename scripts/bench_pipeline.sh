#!/usr/bin/env bash
# End-to-end throughput of `celc run` on a synthetic DAVIS346 chessboard
# sequence (~0.6 M events/s): with the default settings (windows grown for
# parallax) and with 1,000,000-event windows; then with the default settings
# on the rendered room at 4 m/s (config/scenes/e2e_davis346_room_fast.yaml,
# 1.2 M events/s of sequence: a "1 M events/s" case), three runs. Each run
# once with the default options and once with config/fast.yaml.
# Prints the events/s and the share of time per stage (from summary.md);
# the runs leave the truth labels aside (--truth-labels none).
#   scripts/bench_pipeline.sh [threads (default 2)]
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${CELC_BUILD_DIR:-$root/build}"
threads="${1:-2}"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
# ~0.6 M events per simulated second: 5 s gives 3 windows of 1 M events.
"$build/celc" synth "$root/config/scenes/davis346_chessboard.yaml" -o "$work/seq" --duration 5 -q
configs=(default fast)
for policy in default events; do
  args=()
  [ "$policy" = events ] && args=(--window-events 1000000)
  for cfg in "${configs[@]}"; do
    cfg_args=()
    [ "$cfg" = fast ] && cfg_args=(-c "$root/config/fast.yaml")
    "$build/celc" run "$work/seq" -o "$work/out-$policy-$cfg" "${args[@]}" "${cfg_args[@]}" --threads "$threads" \
      --no-plots -q --truth-labels none > /dev/null
    echo "celc run, ${args[*]:-default windows}, $cfg options, $threads threads:"
    grep -E "windows processed|time per stage" "$work/out-$policy-$cfg/summary.md"
    grep -E "^\| (celc|celc_opt|celc_ml|ce3lc) " "$work/out-$policy-$cfg/summary.md" | cut -d'|' -f2,3,4,8,9,12
  done
done
# A sequence of more than 1 M events/s (0.41 s, every window solved).
"$build/celc" synth "$root/config/scenes/e2e_davis346_room_fast.yaml" -o "$work/room" -q
for run in 1 2 3; do
  for cfg in "${configs[@]}"; do
    cfg_args=()
    [ "$cfg" = fast ] && cfg_args=(-c "$root/config/fast.yaml")
    "$build/celc" run "$work/room" -o "$work/out-room-$run-$cfg" "${cfg_args[@]}" --threads "$threads" \
      --no-plots -q --truth-labels none > /dev/null
    echo "celc run, default windows, $cfg options, the 4 m/s room (run $run), $threads threads:"
    grep -E "windows processed|time per stage" "$work/out-room-$run-$cfg/summary.md"
  done
done
