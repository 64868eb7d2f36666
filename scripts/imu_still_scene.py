#!/usr/bin/env python3
"""Give a scene file (stdin -> stdout) the IMU of a sensor that starts at
rest: `imu.still_before_s` seconds of a still camera before the motion (the
still second `celc run` takes gravity from), and an accelerometer with a
MEMS sensor's white noise and a constant bias. The rest of the scene is
unchanged, so its events are the same.

    scripts/imu_still_scene.py [--still S] [--noise N] [--bias BX,BY,BZ] < SCENE.yaml > OUT.yaml

Defaults: 1 s still; 4e-3 m/s^2/sqrt(Hz) (an MPU-6050's 400 ug/sqrt(Hz));
a bias of 0.04,-0.05,0.03 m/s^2 (the size `motion.accel_bias_m_s2` assumes)."""
import argparse
import re
import sys

KEYS = ("still_before_s", "accel_noise", "accel_bias")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--still", type=float, default=1.0, help="seconds at rest before the motion [s]")
    ap.add_argument("--noise", type=float, default=4e-3, help="accelerometer noise density [m/s^2/sqrt(Hz)]")
    ap.add_argument("--bias", default="0.04,-0.05,0.03", help="accelerometer bias [m/s^2], IMU frame")
    args = ap.parse_args()
    bias = [float(x) for x in args.bias.split(",")]
    if len(bias) != 3:
        sys.exit("imu_still_scene.py: --bias needs three numbers")
    ours = [f"  still_before_s: {args.still:g}\n", f"  accel_noise: {args.noise:g}\n",
            "  accel_bias: [%s]\n" % ", ".join(f"{b:g}" for b in bias)]
    lines = sys.stdin.readlines()
    out, in_imu, found = [], False, False
    for line in lines:
        if re.match(r"^imu:\s*(#.*)?$", line):
            in_imu = found = True
            out.append(line)
            out.extend(ours)
            continue
        if in_imu and line.strip() and not line[0].isspace():
            in_imu = False
        if in_imu and re.match(r"^\s+(%s):" % "|".join(KEYS), line):
            continue
        out.append(line)
    if not found:
        if out and not out[-1].endswith("\n"):
            out[-1] += "\n"
        out.append("\nimu:\n")
        out.extend(ours)
    sys.stdout.writelines(out)


if __name__ == "__main__":
    main()
