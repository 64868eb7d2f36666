#!/usr/bin/env bash
# End-to-end accuracy of `celc run` with no options on every shipped scene
# (config/scenes/*.yaml) and on held-out variants of them that no default was
# chosen on (other seeds, speeds, noise, sensor): renders each once with
# `celc synth` (cached under OUTDIR/seq), runs it, and prints a markdown table
# of the median phi [rad] per method with ok windows / windows.
#   scripts/scene_table.sh [OUTDIR] [-- extra celc run arguments]
# Then the same over all windows of every scene. Default OUTDIR out/scenes;
# about 8 minutes on 2 cores (rendering included). CELC_SCENE_FILTER, when
# set, is a command every scene file passes through (stdin to stdout) before
# it is rendered, e.g. scripts/imu_still_scene.py.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
out="$root/out/scenes"
if [ $# -gt 0 ] && [ "$1" != "--" ]; then out="$1"; shift; fi
[ "${1:-}" = "--" ] && shift
extra=("$@")
celc="${CELC_BINARY:-$root/build/celc}"
[ -x "$celc" ] || "$root/scripts/setup.sh"
mkdir -p "$out/seq" "$out/run"

# Held-out variants: name | base scene | sed edits
heldout=(
  "heldout_room_seed5_noise|e2e_davis346_room_fast|s/^seed: 1/seed: 5/;s/^duration: 0.41/duration: 0.6/;s/noise_rate: 0.1 /noise_rate: 1.0 /;s/v: \[3.2, -0.6, 2.4\]/v: [2.0, 0.4, 1.5]/"
  "heldout_handheld_seed7|handheld_fast_rotation|s/^seed: 3/seed: 7/;s/v: \[0.3, 0.1, 1.3\]/v: [0.6, -0.2, 1.0]/;s/w: \[0.4, -1.4, 0.6\]/w: [-0.8, 1.1, 0.3]/"
  "heldout_room_slow_rotating|e2e_davis346_room_fast|s/^seed: 1/seed: 9/;s/^duration: 0.41/duration: 0.8/;s/v: \[3.2, -0.6, 2.4\]/v: [1.2, 0.3, 0.9]/;s/w: \[0.1, -0.25, 0.15\]/w: [0.6, 0.9, -0.4]/"
  "heldout_braking_room|accelerating_room|s/^seed: 11/seed: 12/;s/v: \[1.2, -0.2, 0.9\]/v: [1.6, -0.3, 1.2]/;s/acceleration: \[1.5, -0.3, 1.2\]/acceleration: [-1.5, 0.3, -1.2]/"
  "heldout_davis240_forward|davis240_rectangles|s/^seed: 2/seed: 6/;s/type: sinusoid /type: constant_twist /;s/v: \[0.4, 0.0, 0.1\]/v: [0.3, -0.2, 1.5]/;s/w: \[0.0, 0.0, 0.0\]/w: [0.3, 0.5, -0.2]/;/amplitude_v\|amplitude_w\|frequency/d"
)
scenes=()
for f in "$root"/config/scenes/*.yaml; do scenes+=("$(basename "$f" .yaml)|$f|"); done
for h in "${heldout[@]}"; do
  IFS='|' read -r name base edits <<<"$h"
  scenes+=("$name|$root/config/scenes/$base.yaml|$edits")
done
# And the seeded random held-out set (scripts/heldout_scenes.py).
/usr/bin/python3 "$root/scripts/heldout_scenes.py" "$out/heldout" --count 16 > /dev/null
for f in "$out"/heldout/*.yaml; do scenes+=("$(basename "$f" .yaml)|$f|"); done

methods="celc celc_opt celc_ml ce3lc npt celc_acc"
printf '| scene | events | seconds | celc | celc_opt | celc_ml | ce3lc | npt | celc_acc |\n|---|---|---|---|---|---|---|---|---|\n'
for s in "${scenes[@]}"; do
  IFS='|' read -r name file edits <<<"$s"
  seq="$out/seq/$name"
  sed -e "${edits:-s/^//}" "$file" | ${CELC_SCENE_FILTER:-cat} >"$out/seq/$name.yaml"
  if [ ! -f "$seq/events.txt" ] || ! cmp -s "$out/seq/$name.yaml" "$seq/.scene.yaml"; then
    "$celc" synth "$out/seq/$name.yaml" -o "$seq" --force -q
    cp "$out/seq/$name.yaml" "$seq/.scene.yaml"
  fi
  "$celc" run "$seq" -o "$out/run/$name" --force -q "${extra[@]}" >/dev/null
  n_events=$(wc -l <"$seq/events.txt")
  seconds=$(awk 'NR == 1 { t0 = $1 } { t = $1 } END { printf "%.2f", t - t0 }' "$seq/events.txt")
  row="| $name | $n_events | $seconds |"
  for m in $methods; do
    # summary.md columns: method, windows, ok, with gt, mean eps, median eps, mean phi, median phi
    cell=$(awk -F'|' -v m=" $m " '$2 == m { gsub(/ /, "", $9); gsub(/ /, "", $4); gsub(/ /, "", $3);
            printf "%s (%s/%s)", $9, $4, $3; exit }' "$out/run/$name/summary.md")
    row="$row ${cell:--} |"
  done
  echo "$row"
done
# Over every window of every scene: ok / windows, the median phi of the ok
# windows and the shares within 0.05 and 0.1 rad; then the share of the
# scenes' time covered by ok windows within 0.1 rad (a window's end clipped to
# its scene's last event; a refused window counts as a miss), which compares
# runs whose windows differ in number or length.
spans="$out/run/.spans"
: >"$spans"
for d in "$out"/run/*/; do
  name=$(basename "$d")
  ev="$out/seq/$name/events.txt"
  [ -f "$ev" ] && [ -f "$d/windows.csv" ] || continue
  printf '%s %s %s\n' "$d/windows.csv" "$(head -n 1 "$ev" | cut -d' ' -f1)" "$(tail -n 1 "$ev" | cut -d' ' -f1)" >>"$spans"
done
echo
printf '| method | ok / windows | median phi [rad] | phi <= 0.05 | phi <= 0.1 | time within 0.1 rad | kept but wrong: all / hand-held |\n'
printf '|---|---|---|---|---|---|---|\n'
for m in $methods; do
  time_share=$(while read -r csv t_first t_last; do
      awk -F, -v m="$m" -v f="$t_first" -v l="$t_last" 'NR == 1 { print "span", l - f }
        $1 != "window" && $6 == m && $7 == "ok" && $15 != "" && $15 <= 0.1 {
          e = $3 < l ? $3 : l; print "in", e - $2 }' "$csv"
    done <"$spans" | awk '$1 == "span" { s += $2 } $1 == "in" { i += $2 } END { printf "%.3f", (s > 0 ? i / s : 0) }')
  # Kept but wrong: ok windows with sigma_deg < 5 deg and phi > 0.1 rad; all
  # scenes, then the hand-held ones (names with "hand").
  kept_wrong=$(for d in "$out"/run/*/; do
      awk -F, -v m="$m" -v hand="$(basename "$d" | grep -c hand)" '$1 != "window" && $6 == m && $7 == "ok" &&
        $15 != "" && $18 != "" && $18 + 0 < 5 && $15 + 0 > 0.1 { n++; if (hand) h++ }
        END { print n + 0, h + 0 }' "$d/windows.csv"
    done | awk '{ n += $1; h += $2 } END { printf "%d / %d", n, h }')
  cat "$out"/run/*/windows.csv | awk -F, -v m="$m" '$1 != "window" && $6 == m { n++; if ($7 == "ok" && $15 != "") print $15 }
    END { print "n", n }' | sort -g | awk -v m="$m" -v ts="$time_share" -v kw="$kept_wrong" '
    $1 == "n" { n = $2; next } { p[++k] = $1; if ($1 <= 0.05) a++; if ($1 <= 0.1) b++ }
    END { med = k ? (k % 2 ? p[(k + 1) / 2] : (p[k / 2] + p[k / 2 + 1]) / 2) : 0
          printf "| %s | %d / %d | %.3f | %.2f | %.2f | %s | %s |\n", m, k, n, med, k ? a / k : 0, k ? b / k : 0, ts, kw }'
done
