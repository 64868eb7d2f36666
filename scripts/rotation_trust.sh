#!/usr/bin/env bash
# Pure rotation under realistic calibration errors: does any method answer
# with confidence? The bundled sample's room (config/scenes/sample_davis346_room.yaml)
# rendered with the camera only turning (roll about z, pan about y, tilt
# about x, at 0.3, 1 and 3 rad/s, 0.6 s each), an IMU with a 0.01 rad/s gyro
# bias and turned 1 deg from the camera; then run with what a user's
# calibration gets wrong: principal point 3 px off, focal length 1% off,
# radial distortion 10% off, gyro scale 1% off (the IMU file's rates x 1.01),
# the IMU taken as aligned with the camera. Every window policy: the default
# (parallax), 0.2 s windows and 80,000-event windows.
#   scripts/rotation_trust.sh [OUTDIR]          (default out/rotation-trust; about 5 minutes)
# Prints one row per sequence and policy: windows, ok rows, and ok rows with
# sigma_deg < 10 deg (confident), with the worst of those; then the total.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
out="${1:-$root/out/rotation-trust}"
celc="${CELC_BINARY:-${CELC_BUILD_DIR:-$root/build}/celc}"
[ -x "$celc" ] || "$root/scripts/setup.sh"
py=/usr/bin/python3
mkdir -p "$out"
printf '| sequence | policy | windows | ok rows | confident rows (sigma_deg < 10) |\n|---|---|---|---|---|\n'
total=0
for axis in roll pan tilt; do
  for rate in 0.3 1 3; do
    case "$axis" in
      roll) w="[0, 0, $rate]" ;;
      pan) w="[0, $rate, 0]" ;;
      tilt) w="[$rate, 0, 0]" ;;
    esac
    name="${axis}_${rate}"
    seq="$out/$name"
    sed -e "s/^duration:.*/duration: 0.6/" -e "s/^  v: \[.*/  v: [0, 0, 0]/" -e "s/^  w: \[.*/  w: $w/" \
        -e "s/^  gyro_bias: .*/  gyro_bias: [0.0058, -0.0058, 0.0058]/" \
        -e "s/^  R_cam_imu: .*/  R_cam_imu: [1, 0, 0, 0, 0.9998476952, -0.0174524064, 0, 0.0174524064, 0.9998476952]/" \
        "$root/config/scenes/sample_davis346_room.yaml" > "$out/$name.yaml"
    if [ ! -f "$seq/events.txt" ] || ! cmp -s "$out/$name.yaml" "$seq/.scene.yaml"; then
      "$celc" synth "$out/$name.yaml" -o "$seq" --force -q
      cp "$out/$name.yaml" "$seq/.scene.yaml"
      # Gyro scale 1% off: the IMU file's rates (columns 5-7 of t ax ay az wx wy wz) x 1.01.
      $py - "$seq/imu.txt" <<'EOF'
import sys
path = sys.argv[1]
rows = [line.split() for line in open(path) if line.strip()]
with open(path, "w") as f:
    for r in rows:
        f.write(" ".join(r[:4] + ["%.9g" % (1.01 * float(x)) for x in r[4:7]]) + "\n")
EOF
    fi
    # The calibration a user measured: principal point +3 px, focal +1%, radial terms
    # +10%, the IMU taken as aligned with the camera.
    $py - "$seq/calib.yaml" "$seq/calib_off.yaml" <<'EOF'
import re, sys
text = open(sys.argv[1]).read()
def scale(key, f, add=0.0):
    global text
    text = re.sub(r"(\n  %s: )([-0-9.e]+)" % key, lambda m: m.group(1) + "%.9g" % (float(m.group(2)) * f + add), text)
scale("fx", 1.01); scale("fy", 1.01); scale("cx", 1.0, 3.0); scale("cy", 1.0, 3.0)
m = re.search(r"distortion: \[([^\]]*)\]", text)
d = [float(x) for x in m.group(1).split(",")]
d[0] *= 1.1; d[1] *= 1.1
text = text.replace(m.group(0), "distortion: [" + ", ".join("%.9g" % x for x in d) + "]")
text = re.sub(r"R_cam_imu: \[[^\]]*\]", "R_cam_imu: [1, 0, 0, 0, 1, 0, 0, 0, 1]", text)
open(sys.argv[2], "w").write(text)
EOF
    for policy in parallax seconds events; do
      case "$policy" in
        parallax) args=() ;;
        seconds) args=(--window-seconds 0.2) ;;
        events) args=(--window-events 80000) ;;
      esac
      run="$out/run/$name-$policy"
      "$celc" run "$seq" --calib "$seq/calib_off.yaml" "${args[@]}" -o "$run" --force -q --no-plots > /dev/null
      row=$($py - "$run/windows.csv" <<'EOF'
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
windows = len({r["window"] for r in rows})
ok = [r for r in rows if r["status"] == "ok"]
conf = [r for r in ok if r["sigma_deg"] and float(r["sigma_deg"]) < 10.0]
worst = min((float(r["sigma_deg"]) for r in conf), default=None)
detail = "" if not conf else " (smallest %.1f deg: %s)" % (worst, ", ".join(sorted({r["method"] for r in conf})))
print("%d | %d | %d%s" % (windows, len(ok), len(conf), detail))
EOF
)
      printf '| %s | %s | %s |\n' "$name" "$policy" "$row"
      total=$((total + $(echo "$row" | cut -d'|' -f3 | awk '{print $1}')))
    done
  done
done
printf '\nconfident rows in all: %d\n' "$total"
