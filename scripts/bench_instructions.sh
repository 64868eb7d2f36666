#!/usr/bin/env bash
# Instructions that `celc run` executes, in total and per stage, counted by
# valgrind's callgrind: a comparison of two builds that the machine's speed
# swings (up to 1.3x between runs) do not blur. The run is on one thread
# (--threads 1 --set cluster.threads=1), so that each stage's count holds
# everything it calls. Instructions are not time (cache misses, the second
# core), so a change is also timed with bench_formats.sh.
#   scripts/bench_instructions.sh [SEQ [celc run args...]]
# SEQ defaults to the 4 m/s room (config/scenes/e2e_davis346_room_fast.yaml,
# rendered by celc synth; about 2 minutes per build under callgrind).
# Environment: CELC_BUILD_DIR (default build/); CELC_OLD_BUILD, another build
# directory (or a folder holding an old celc and its libcelc_*.so): it is
# counted too, its counts and the ratio are printed beside this build's, and
# both runs' windows.csv must be the same (scripts/same_windows.py).
# Installs valgrind (Debian package) when it is missing.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${CELC_BUILD_DIR:-$root/build}"
old="${CELC_OLD_BUILD:-}"
if ! command -v valgrind > /dev/null || ! command -v callgrind_annotate > /dev/null; then
  sudo_cmd=()
  [ "$(id -u)" -ne 0 ] && sudo_cmd=(sudo)
  "${sudo_cmd[@]}" apt-get update -qq
  DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends valgrind >&2
fi
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
seq="${1:-}"
[ "$#" -gt 0 ] && shift
if [ -z "$seq" ]; then
  seq="$work/room"
  "$build/celc" synth "$root/config/scenes/e2e_davis346_room_fast.yaml" -o "$seq" -q
fi

# The stages: a label and the function whose inclusive count it is (a
# prefix of callgrind's demangled name). Redraws include their own line
# fits and solves, which the rows above them also count.
stages=(
  "whole run|celc::runSequence("
  "clustering (grid grower)|celc::clusterEvents("
  "moving-line cut|celc::splitByMovingLines("
  "undistortion and lines|celc::toObservations("
  "solvers|celc::solveMethods("
  "redraws under the motion|celc::SequenceRunner::Impl::redrawUnderMotion("
)

# count NAME DIR: runs DIR's celc under callgrind; leaves NAME.out and NAME/windows.csv.
count() {
  local name="$1" dir="$2" lib=()
  shift 2
  [ -f "$dir/libcelc_core.so" ] && lib=(env "LD_LIBRARY_PATH=$dir")
  "${lib[@]}" valgrind --tool=callgrind --callgrind-out-file="$work/$name.out" \
    "$dir/celc" run "$seq" -o "$work/$name" --threads 1 --set cluster.threads=1 --no-plots -q \
    --truth-labels none "$@" > "$work/$name.log" 2>&1 || {
    echo "celc run under callgrind failed ($dir): see below" >&2
    tail -5 "$work/$name.log" >&2
    exit 1
  }
  callgrind_annotate --inclusive=yes --threshold=100 "$work/$name.out" 2> /dev/null > "$work/$name.txt"
}
# inclusive NAME PREFIX: the largest inclusive count of a function named PREFIX...
inclusive() {
  /usr/bin/python3 - "$work/$1.txt" "$2" <<'PY'
import re, sys
best = 0
for line in open(sys.argv[1]):
    m = re.match(r"\s*([\d,]+) \([ \d.]+%\)\s+\S*?:(.*)", line)
    if m and m.group(2).startswith(sys.argv[2]):
        best = max(best, int(m.group(1).replace(",", "")))
print(best)
PY
}

count new "$build" "$@"
[ -n "$old" ] && count old "$old" "$@"
echo "celc run $seq, one thread: instructions (callgrind)"
if [ -n "$old" ]; then
  echo "| stage | this build [G instructions] | CELC_OLD_BUILD [G instructions] | ratio |"
  echo "|---|---|---|---|"
else
  echo "| stage | G instructions |"
  echo "|---|---|"
fi
for s in "${stages[@]}"; do
  label="${s%%|*}"
  fn="${s#*|}"
  n=$(inclusive new "$fn")
  if [ -n "$old" ]; then
    o=$(inclusive old "$fn")
    awk -v l="$label" -v n="$n" -v o="$o" 'BEGIN { r = "-"; if (o > 0) r = sprintf("%.3f", n / o); printf "| %s | %.3f | %.3f | %s |\n", l, n / 1e9, o / 1e9, r }'
  else
    awk -v l="$label" -v n="$n" 'BEGIN { printf "| %s | %.3f |\n", l, n / 1e9 }'
  fi
done
if [ -n "$old" ]; then
  /usr/bin/python3 "$root/scripts/same_windows.py" "$work/old/windows.csv" "$work/new/windows.csv"
fi
