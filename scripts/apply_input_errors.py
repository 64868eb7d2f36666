#!/usr/bin/env python3
"""Give a rendered sequence the calibration a user with a real sensor has:
apply ERRORS.json (written by scripts/heldout_scenes.py --input-errors) to
SEQDIR, rendered by `celc synth`. Writes SEQDIR/calib_user.yaml (principal
point moved by principal_point_px [px], focal lengths times 1 + focal_share,
the IMU taken as aligned with the camera) and rewrites SEQDIR/imu.txt with
each gyro axis's rate times 1 + gyro_scale (run it once per rendering).

    scripts/apply_input_errors.py SEQDIR ERRORS.json
"""
import json
import os
import re
import sys


def main():
    if len(sys.argv) != 3:
        raise SystemExit(__doc__.strip().split("\n\n")[-1])
    seq, errors_path = sys.argv[1], sys.argv[2]
    e = json.load(open(errors_path))
    text = open(os.path.join(seq, "calib.yaml")).read()

    def change(key, f):
        nonlocal text
        text, n = re.subn(r"(\n\s*%s: )([-0-9.e]+)" % key, lambda m: m.group(1) + "%.9g" % f(float(m.group(2))), text)
        if n != 1:
            raise SystemExit(f"{seq}/calib.yaml: no single '{key}:'")
    change("fx", lambda x: x * (1.0 + e["focal_share"]))
    change("fy", lambda x: x * (1.0 + e["focal_share"]))
    change("cx", lambda x: x + e["principal_point_px"][0])
    change("cy", lambda x: x + e["principal_point_px"][1])
    text, n = re.subn(r"R_cam_imu: \[[^\]]*\]", "R_cam_imu: [1, 0, 0, 0, 1, 0, 0, 0, 1]", text)
    if n != 1:
        raise SystemExit(f"{seq}/calib.yaml: no R_cam_imu")
    with open(os.path.join(seq, "calib_user.yaml"), "w") as f:
        f.write(text)
    imu = os.path.join(seq, "imu.txt")
    rows = [line.split() for line in open(imu) if line.strip() and not line.startswith("#")]
    with open(imu, "w") as f:
        for r in rows:  # t ax ay az wx wy wz
            w = ["%.9g" % (float(x) * (1.0 + s)) for x, s in zip(r[4:7], e["gyro_scale"])]
            f.write(" ".join(r[:4] + w) + "\n")


if __name__ == "__main__":
    main()
