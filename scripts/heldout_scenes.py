#!/usr/bin/env python3
"""Write a held-out set of scene files: random variants of the shipped
rendered scenes (config/scenes), drawn from a fixed seed, that no default was
chosen on. Each variant takes one of three base scenes (the room, the
hand-held room with its sinusoidal rotation, the rectangles wall as a
constant twist) and draws a new scene seed, a speed of 0.8-3 m/s and a
rotation rate of 0.2-2.5 rad/s in random directions, and a background noise
rate; durations are 0.6 s. `--kinds` chooses other bases: `deep` is the slow,
deep scene (slow_deep.yaml: 3-6 m away) as a constant twist at 0.5-1.5 m/s
and 0.05-1 rad/s for 2 s, long enough for two windows of a second; `lines`
is a scene of straight bars and nothing else (a far wall at 5-6 m with 4
bars 0.5-1.2 m long, two planes at 3-4 m with 2 bars each, placed and
turned at random: 10-40 straight edges in view), as a constant twist at
1-4 m/s and 0.3-3 rad/s for 0.6 s. Render them with `celc synth FILE -o DIR`.

    scripts/heldout_scenes.py OUTDIR [--count N] [--seed S] [--kinds room,hand,rect,deep,lines]
                              [--speed LO,HI] [--rate LO,HI] [--input-errors]

--input-errors gives every scene the errors of a real sensor's inputs, drawn
at the 1-sigma sizes of sigma_deg's default budget (docs/accuracy.md): the
rendered IMU gets a gyro bias of N(0, 0.01) rad/s per axis and is turned
N(0, 1) deg about each axis from the camera; OUTDIR/hNN_<base>.errors.json
holds what the user's calibration then gets wrong (principal point N(0, 3)
px per axis, focal length N(0, 1)%, gyro scale N(0, 1)% per axis, the IMU
taken as aligned), which scripts/apply_input_errors.py applies to the
rendered sequence. The scenes' motions are those drawn without the option.

--speed [m/s] and --rate [rad/s] replace every kind's ranges (e.g. 1,1 for
1 m/s at every scene).

Writes OUTDIR/hNN_<base>.yaml and prints one line per scene (its motion)."""
import argparse
import json
import math
import os
import random
import re

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BASES = {"room": "e2e_davis346_room_fast", "hand": "handheld_fast_rotation", "rect": "davis240_rectangles",
         "deep": "slow_deep", "lines": "slow_deep"}  # lines: slow_deep's camera, events and IMU, its own planes
# Per kind: speed [m/s], rotation rate [rad/s], duration [s].
RANGES = {"room": ((0.8, 3.0), (0.2, 2.5), 0.6), "hand": ((0.8, 3.0), (0.2, 2.5), 0.6),
          "rect": ((0.8, 3.0), (0.2, 2.5), 0.6), "deep": ((0.5, 1.5), (0.05, 1.0), 2.0),
          "lines": ((1.0, 4.0), (0.3, 3.0), 0.6)}


def random_vector(rng, norm):
    """A vector of the given norm in a uniformly random direction."""
    while True:
        v = [rng.uniform(-1.0, 1.0) for _ in range(3)]
        n = math.sqrt(sum(x * x for x in v))
        if 0.2 < n <= 1.0:
            return [round(norm * x / n, 2) for x in v]


def set_key(text, pattern, value):
    """Replace the first match of `pattern` (group 1 kept) with group 1 + value."""
    new, n = re.subn(pattern, lambda m: m.group(1) + value, text, count=1, flags=re.M)
    if n != 1:
        raise SystemExit(f"heldout_scenes.py: no match for {pattern!r}")
    return new


def bars_plane(rng, position, rotation, size, count):
    """One `segments` plane of `count` long bars (YAML lines of the planes list)."""
    fmt = lambda xs: "[" + ", ".join(f"{x:.3f}" for x in xs) + "]"
    return (f"  - texture: segments\n"
            f"    position: {fmt(position)}\n"
            f"    rotation: {fmt(rotation)}\n"
            f"    size: {fmt(size)}\n"
            f"    base: {rng.uniform(0.45, 0.65):.2f}\n"
            f"    count: {count}\n"
            f"    length_range: [0.5, 1.2]\n"
            f"    width_range: [0.04, 0.1]\n"
            f"    intensity_range: [0.05, 0.3]\n")


def lines_planes(rng):
    """The planes of a `lines` scene: a far wall of 4 bars and two nearer planes of 2 bars each."""
    planes = bars_plane(rng, [rng.uniform(-0.5, 0.5), rng.uniform(-0.3, 0.3), rng.uniform(5.0, 6.0)],
                        [rng.uniform(-0.2, 0.2), rng.uniform(-0.3, 0.3), rng.uniform(-0.5, 0.5)], [7.0, 5.0], 4)
    for side in (-1.0, 1.0):
        planes += bars_plane(rng, [side * rng.uniform(0.6, 1.2), rng.uniform(-0.6, 0.6), rng.uniform(3.0, 4.0)],
                             [rng.uniform(-0.3, 0.3), side * rng.uniform(0.1, 0.3), rng.uniform(-0.8, 0.8)],
                             [2.2, 2.2], 2)
    return planes


def variant(rng, index, kind, base, speed_range=None, rate_range=None):
    text = open(os.path.join(ROOT, "config", "scenes", base + ".yaml")).read()
    if kind == "lines":  # slow_deep's planes replaced by planes of bars, its description dropped
        text = re.sub(r"\A(?:#.*\n)+", "# Straight bars only: a far wall and two nearer planes (scripts/heldout_scenes.py).\n"
                      "# Units: metres [m], seconds [s], radians [rad], pixels [px]. Schema: docs/simulation.md.\n", text)
        text = re.sub(r"^planes:\n(?:(?:  .*)?\n)*?(?=trajectory:)", lambda m: "planes:\n" + lines_planes(rng) + "\n",
                      text, count=1, flags=re.M)
    speeds, rates, duration = RANGES[kind]
    speeds, rates = speed_range or speeds, rate_range or rates
    speed, rate = rng.uniform(*speeds), rng.uniform(*rates)
    v, w = random_vector(rng, speed), random_vector(rng, rate)
    noise = rng.choice([0.1, 0.5, 1.0, 2.0])
    text = set_key(text, r"^(seed: )\d+", str(1000 + index))
    text = set_key(text, r"^(duration: )[0-9.]+", str(duration))
    if kind == "rect":  # the shipped wall moves sinusoidally: here a constant twist
        text = set_key(text, r"^(\s*type: )sinusoid", "constant_twist")
        text = re.sub(r"^\s*(amplitude_v|amplitude_w|frequency):.*\n", "", text, flags=re.M)
    text = set_key(text, r"^(\s*v: )\[[^\]]*\].*", f"{v}  # camera-frame linear velocity [m/s] (|v| = {speed:.2f})")
    text = set_key(text, r"^(\s*w: )\[[^\]]*\].*", f"{w}  # camera-frame angular velocity [rad/s] (|w| = {rate:.2f})")
    text = set_key(text, r"^(\s*noise_rate: )[0-9.]+", str(noise))
    source = "the lines kind (slow_deep.yaml's camera, events and IMU)" if kind == "lines" else base + ".yaml"
    header = (f"# Held-out variant {index} of {source} (scripts/heldout_scenes.py): "
              f"speed {speed:.2f} m/s, rotation {rate:.2f} rad/s, noise {noise} Hz/px.\n")
    return header + text, f"speed {speed:.2f} m/s v {v}, rotation {rate:.2f} rad/s w {w}, noise {noise}"


def rotation_matrix(rx, ry, rz):
    """Row-major R = Rz Ry Rx for small angles about x, y, z [rad]."""
    cx, sx, cy, sy, cz, sz = math.cos(rx), math.sin(rx), math.cos(ry), math.sin(ry), math.cos(rz), math.sin(rz)
    return [cz * cy, cz * sy * sx - sz * cx, cz * sy * cx + sz * sx,
            sz * cy, sz * sy * sx + cz * cx, sz * sy * cx - cz * sx,
            -sy, cy * sx, cy * cx]


def input_errors(text, seed, index):
    """The scene with a drawn gyro bias and IMU rotation, and the calibration errors (a dict)."""
    rng = random.Random(seed * 7919 + index)
    bias = [round(rng.gauss(0.0, 0.01), 5) for _ in range(3)]
    angles = [rng.gauss(0.0, math.radians(1.0)) for _ in range(3)]
    R = rotation_matrix(*angles)
    text = set_key(text, r"^(\s*gyro_bias: )\[[^\]]*\]", str(bias))
    text = set_key(text, r"^(\s*R_cam_imu: )\[[^\]]*\]", "[" + ", ".join("%.10f" % x for x in R) + "]")
    errors = {"principal_point_px": [round(rng.gauss(0.0, 3.0), 3) for _ in range(2)],
              "focal_share": round(rng.gauss(0.0, 0.01), 5),
              "gyro_scale": [round(rng.gauss(0.0, 0.01), 5) for _ in range(3)],
              "gyro_bias_rad_s": bias, "imu_rotation_deg": [round(math.degrees(x), 4) for x in angles]}
    return text, errors


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("outdir")
    ap.add_argument("--count", type=int, default=16, help="scenes to write (default 16)")
    ap.add_argument("--seed", type=int, default=2026, help="seed of the draw (default 2026)")
    ap.add_argument("--kinds", default="room,hand,rect",
                    help="bases, taken in turn: room, hand, rect, deep, lines (default room,hand,rect)")
    ap.add_argument("--speed", help="speed range LO,HI [m/s] for every kind")
    ap.add_argument("--rate", help="rotation rate range LO,HI [rad/s] for every kind")
    ap.add_argument("--input-errors", action="store_true",
                    help="a real sensor's gyro and calibration errors (see above)")
    a = ap.parse_args()

    def pair(text, name):
        if text is None:
            return None
        try:
            lo, hi = (float(x) for x in text.split(","))
        except ValueError:
            raise SystemExit(f"heldout_scenes.py: --{name}: expected LO,HI, got {text!r}")
        if not (0 <= lo <= hi):
            raise SystemExit(f"heldout_scenes.py: --{name}: need 0 <= LO <= HI, got {text!r}")
        return (lo, hi)
    speed_range, rate_range = pair(a.speed, "speed"), pair(a.rate, "rate")
    if a.count < 1:
        raise SystemExit("heldout_scenes.py: --count must be >= 1")
    kinds = a.kinds.split(",")
    for k in kinds:
        if k not in BASES:
            raise SystemExit(f"heldout_scenes.py: --kinds: unknown kind {k!r} (room, hand, rect, deep, lines)")
    os.makedirs(a.outdir, exist_ok=True)
    rng = random.Random(a.seed)
    for i in range(a.count):
        kind = kinds[i % len(kinds)]
        base = BASES[kind]
        text, motion = variant(rng, i, kind, base, speed_range, rate_range)
        name = f"h{i:02d}_{kind}"
        if a.input_errors:
            text, errors = input_errors(text, a.seed, i)
            with open(os.path.join(a.outdir, name + ".errors.json"), "w") as f:
                json.dump(errors, f, indent=1)
        with open(os.path.join(a.outdir, name + ".yaml"), "w") as f:
            f.write(text)
        print(f"{name}: {motion}")


if __name__ == "__main__":
    main()
