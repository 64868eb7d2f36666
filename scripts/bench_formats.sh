#!/usr/bin/env bash
# `celc run` end to end on one rendered recording stored four ways: text
# (events.txt), AEDAT 4 (lz4), ROS bag (lz4 chunks) and HDF5 (MVSEC layout).
# For each input, 1 and 2 threads, the default (parallax-grown) windows and
# 1,000,000-event windows, it prints a Markdown table: events/s end to end,
# events/s per stage (events over the summed time of the stage: reading
# without the probes, the parallax probes, clustering, undistortion + lines,
# solvers, the redraws under the motion; M events/s), the peak resident set and the bound
# 2 x (largest window's events) x 24 B + 150 MB. The stage times are summed
# over the windows; with 2 threads they overlap (and share the cores).
#   scripts/bench_formats.sh [SECONDS (default 5)]
# Environment: CELC_BUILD_DIR (default build/); CELC_OLD_BUILD, another build
# directory (or a folder holding an old celc and its libcelc_*.so): each case
# then also runs it, alternating with this build, adds its events/s and the
# ratio, and checks that both give the same windows.csv (scripts/same_windows.py).
# The bag and HDF5 files are written by celc_make_fixtures (the test tree's
# bag writer and libhdf5), AEDAT 4 with the Python module.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${CELC_BUILD_DIR:-$root/build}"
old="${CELC_OLD_BUILD:-}"
seconds="${1:-5}"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT

"$build/celc" synth "$root/config/scenes/davis346_chessboard.yaml" -o "$work/seq" --duration "$seconds" -q
PYTHONPATH="$build/python" /usr/bin/python3 - "$work/seq" "$work" <<'PY'
import sys
import celc
seq, out = sys.argv[1], sys.argv[2]
ev = celc.read_events(seq)
imu = celc.read_imu(seq)
celc.write_events(out + "/seq.aedat4", ev, format="aedat4", imu=imu, width=346, height=260, compression="lz4")
PY
"$build/celc_make_fixtures" "$work/seq" "$work" seq_lz4.bag seq_mvsec.h5
mv "$work/seq_lz4.bag" "$work/seq.bag"
mv "$work/seq_mvsec.h5" "$work/seq.h5"

extra=(--calib "$work/seq/calib.yaml" --groundtruth "$work/seq/groundtruth.txt")
# run BUILD INPUT OUT ARGS...: prints "wall_s rss_kb" and leaves OUT/log.
run() {
  local b="$1" in="$2" out="$3"
  shift 3
  local args=("$@")
  [ "$in" = "$work/seq" ] || args+=("${extra[@]}")
  LD_LIBRARY_PATH="$b${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}" /usr/bin/time -f "%e %M" -o "$out.time" \
    "$b/celc" run "$in" -o "$out" "${args[@]}" --no-plots -v --truth-labels none > /dev/null 2> "$out.log"
  cat "$out.time"
}

echo "| input | threads | windows | events | M events/s end to end |${old:+ CELC_OLD_BUILD M events/s (ratio) |} reading [M events/s] | probes | clustering | lines | solvers | redraws | peak RSS [MB] | bound [MB] |"
echo "|---|---|---|---|---|${old:+---|}---|---|---|---|---|---|---|---|"
status=0
for input in text aedat4 bag hdf5; do
  case "$input" in
    text) in="$work/seq" ;;
    aedat4) in="$work/seq.aedat4" ;;
    bag) in="$work/seq.bag" ;;
    hdf5) in="$work/seq.h5" ;;
  esac
  for policy in default events; do
    pargs=()
    [ "$policy" = events ] && pargs=(--window-events 1000000)
    for threads in 1 2; do
      tag="$input-$policy-$threads"
      old_rate="-"
      if [ -n "$old" ]; then
        read -r old_wall _ < <(run "$old" "$in" "$work/old-$tag" "${pargs[@]}" --threads "$threads")
      fi
      read -r wall rss < <(run "$build" "$in" "$work/new-$tag" "${pargs[@]}" --threads "$threads")
      line="$(grep -o 'stage seconds: .*' "$work/new-$tag.log" | tail -1)"
      # reading R (of which parallax probes P), clustering C, undistortion+lines L, solvers S, redraws D, ...; N events in W s
      python3 - "$line" "$wall" "$rss" "$work/new-$tag/windows.csv" "$input" "$threads" "$policy" \
        "${old:+$work/old-$tag}" "${old_wall:-}" <<'PY'
import csv, re, sys
line, wall, rss, windows, name, threads, policy, old_dir, old_wall = sys.argv[1:10]
num = lambda key: float(re.search(key + r" ([0-9.]+)", line).group(1))
read, probe, clus, lines, solve, redraw = (num("reading"), num("parallax probes"), num("clustering"),
                                           num("undistortion\\+lines"), num("solvers"), num("redraws"))
events = int(re.search(r"; (\d+) events", line).group(1))
with open(windows) as f:
    rows = list(csv.DictReader(f))
sizes = {}
for r in rows:
    sizes[r["window"]] = int(r["n_events"])
rate = lambda s: "%.2f" % (events / s / 1e6) if s > 0 else "-"
e2e = events / float(wall) / 1e6
old = ""
if old_dir:
    o = events / float(old_wall) / 1e6
    old = " %.2f (%.2fx) |" % (o, e2e / o)
bound = 2 * max(sizes.values()) * 24 / 1e6 + 150
label = "default" if policy == "default" else "1 M events"
print("| %s, %s windows | %s | %d | %.2f M | %.2f |%s %s | %s | %s | %s | %s | %s | %.0f | %.0f |" % (
    name, label, threads, len(sizes), events / 1e6, e2e, old, rate(read - probe), rate(probe) if probe > 0 else "-",
    rate(clus), rate(lines), rate(solve), rate(redraw) if redraw > 0 else "-", float(rss) / 1024, bound))
PY
      if [ -n "$old" ] && ! python3 "$root/scripts/same_windows.py" "$work/old-$tag" "$work/new-$tag" > "$work/same-$tag"; then
        cat "$work/same-$tag" >&2
        status=1
      fi
    done
  done
done
[ -z "$old" ] || { [ "$status" = 0 ] && echo "windows.csv: the same with both builds in every case (runtime_ms aside)" \
  || echo "windows.csv: differences (above)"; }
exit "$status"
