#!/usr/bin/env python3
"""Plots of `celc simulate` results, like the paper's Figures 3 and 4.

usage: plot_simulation.py OUTDIR

For every OUTDIR/<sweep>.csv with more than one level it writes
OUTDIR/<sweep>.png: mean eps (left) and mean phi [rad] (right) per method
against the swept parameter, with a +-1 std band. Needs python3-matplotlib.
"""
import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

LABELS = {
    "event_noise": "event noise [px]",
    "line_noise": "line endpoint noise [px]",
    "omega_noise": "angular velocity noise [rad/s]",
    "speed": "speed [m/s]",
    "interval": "time interval [s]",
    "lines": "number of lines",
    "acceleration": "rho = |a| Z / (2 V^2)",
}
STYLE = {"celc": ("C0", "CELC"), "celc_opt": ("C1", "CELC+opt"),
         "celc_ml": ("C2", "CELC+ML (lines refined)"), "ce3lc": ("C3", "CE3LC"),
         "npt": ("C4", "N-point (CVPR'24)"), "celc_acc": ("C5", "CELC+ML, constant acceleration")}


def read(path):
    rows = {}
    with open(path, newline="") as f:
        for r in csv.DictReader(f):
            if not r["eps_mean"]:
                continue  # no trial was ok at this level
            rows.setdefault(r["method"], []).append(r)
    return rows


def plot(outdir, sweep):
    rows = read(os.path.join(outdir, sweep + ".csv"))
    if not rows or max(len(v) for v in rows.values()) < 2:
        return None
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.8))
    for method, rs in rows.items():
        color, label = STYLE.get(method, (None, method))
        x = [float(r["level"]) for r in rs]
        for ax, key in zip(axes, ("eps", "phi")):
            m = [float(r[key + "_mean"]) for r in rs]
            s = [float(r[key + "_std"]) for r in rs]
            ax.plot(x, m, marker="o", ms=3, color=color, label=label)
            ax.fill_between(x, [a - b for a, b in zip(m, s)], [a + b for a, b in zip(m, s)],
                            color=color, alpha=0.15, lw=0)
    for ax, name in zip(axes, ("eps (unit-vector distance)", "phi [rad]")):
        ax.set_xlabel(LABELS.get(sweep, sweep))
        ax.set_ylabel(name)
        ax.set_ylim(bottom=0)
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=8)
    fig.suptitle(f"celc simulate: {sweep} (mean, band = +-1 std)")
    fig.tight_layout()
    png = os.path.join(outdir, sweep + ".png")
    fig.savefig(png, dpi=110)
    plt.close(fig)
    return png


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    outdir = sys.argv[1]
    for name in sorted(os.listdir(outdir)):
        if name.endswith(".csv"):
            png = plot(outdir, name[:-4])
            if png:
                print("wrote", png, file=sys.stderr)


if __name__ == "__main__":
    main()
