#!/usr/bin/env python3
"""celc_ml on the pipeline's clusters against the oracle, window by window.

usage: plot_oracle_gap.py OUT.png LABEL=RUNDIR [LABEL=RUNDIR ...] [--method celc_ml]

Each RUNDIR holds one `celc run` output folder per `celc synth` sequence
(RUNDIR/<name>/windows.csv with the truth columns: scripts/cluster_table.sh
writes them). One point per window with an oracle: x the oracle's phi (celc_ml
on the window's true clusters), y the method's phi on the pipeline's clusters,
both in degrees on log axes (floored at 0.01 deg; a refused window is drawn
at 180 deg). The shaded band is the oracle gap, y <= max(1.5 x, x + 1 deg):
points above it are the windows the clusters cost accuracy. One colour per
LABEL; the legend counts each set's windows within the gap. Needs
python3-matplotlib.
"""
import argparse
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from cluster_quality import oracle_windows  # noqa: E402

FLOOR_DEG = 0.01


def gap_limit_deg(oracle_deg):
    """The most the pipeline may be off and stay within the oracle gap [deg]."""
    return max(1.5 * oracle_deg, oracle_deg + 1.0)


def read_points(rundir, method):
    """(oracle phi, method phi) [deg] of every window with an oracle under rundir."""
    return [(math.degrees(oracle), math.degrees(phi) if phi is not None else 180.0)
            for _, _, phi, oracle in oracle_windows(rundir, method, "plot_oracle_gap.py")]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("out")
    ap.add_argument("sets", nargs="+", metavar="LABEL=RUNDIR")
    ap.add_argument("--method", default="celc_ml")
    a = ap.parse_args()
    fig, ax = plt.subplots(figsize=(5.6, 5.0))
    xs = [FLOOR_DEG * 1.2 ** k for k in range(0, 80)]
    xs = [x for x in xs if x <= 180.0]
    ax.fill_between(xs, [FLOOR_DEG] * len(xs), [min(180.0, gap_limit_deg(x)) for x in xs], color="0.9",
                    label="within max(1.5x, +1 deg) of the oracle")
    ax.plot(xs, xs, color="0.6", lw=0.8, ls="--")
    for k, spec in enumerate(a.sets):
        if "=" not in spec:
            raise SystemExit(f"plot_oracle_gap.py: expected LABEL=RUNDIR, got {spec!r}")
        label, rundir = spec.split("=", 1)
        pts = read_points(rundir, a.method)
        within = sum(1 for o, p in pts if p <= gap_limit_deg(o))
        ax.scatter([max(FLOOR_DEG, o) for o, _ in pts], [max(FLOOR_DEG, p) for _, p in pts], s=14,
                   color=f"C{k}", alpha=0.8, label=f"{label}: {within} of {len(pts)} within")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlim(FLOOR_DEG, 180.0)
    ax.set_ylim(FLOOR_DEG, 200.0)
    ax.set_xlabel("oracle: celc_ml on the true clusters, phi [deg]")
    ax.set_ylabel(f"{a.method} on the pipeline's clusters, phi [deg]")
    ax.set_title("Held-out windows: the clusters' cost in accuracy", fontsize=10)
    ax.legend(fontsize=7, loc="upper left")
    ax.grid(True, which="major", lw=0.3)
    fig.tight_layout()
    fig.savefig(a.out, dpi=110)
    print(f"wrote {a.out}", file=sys.stderr)


if __name__ == "__main__":
    main()
