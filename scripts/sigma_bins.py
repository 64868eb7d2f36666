#!/usr/bin/env python3
"""How well sigma_deg describes the error, per method and per bin of the
window's parallax D (translation_px): < 15, 15-25, >= 25 px, and over all.

    scripts/sigma_bins.py [--plot OUT.png] [--title TEXT] [--compact LABEL [--header]] WINDOWS.csv [...]

Over the ok rows with ground truth and a sigma_deg, per method and bin:
  ok         rows
  coverage   share with phi <= 2 sigma_deg (a calibrated sigma: 0.85-0.99)
  sharp      of the rows within 2 deg, the share with sigma_deg <= 5 deg
  sigma/phi  median of sigma_deg / phi (phi in deg, at least 0.01 deg)
  median sigma_deg, and how often a rule raised it (sigma_rule: disagreement
  d, behind_camera b, ambiguous_nullspace n, accelerometer_refused a)
--compact LABEL prints instead one row per method, labelled LABEL: ok rows,
coverage per bin, sharp and sigma/phi over all (--header: the table's header
first), so that several sets make one table.
--plot writes a reliability plot: phi against sigma_deg per method (log
axes), the lines phi = sigma and phi = 2 sigma. Needs python3-matplotlib for
--plot only. Prints a Markdown table.
"""
import argparse
import csv
import math
import statistics
import sys

METHODS = ["celc", "celc_opt", "celc_ml", "ce3lc", "npt"]
BINS = [("< 15", 0.0, 15.0), ("15-25", 15.0, 25.0), (">= 25", 25.0, math.inf), ("all", -math.inf, math.inf)]
PHI_FLOOR_DEG = 0.01


def num(x):
    try:
        return float(x) if x not in ("", None) else float("nan")
    except ValueError:
        return float("nan")


def read_rows(paths):
    rows = []
    for path in paths:
        try:
            with open(path, newline="") as f:
                for r in csv.DictReader(f):
                    if r.get("status") != "ok":
                        continue
                    phi, sigma = num(r.get("phi")), num(r.get("sigma_deg"))
                    if math.isnan(phi) or math.isnan(sigma):
                        continue
                    d = num(r.get("translation_px"))
                    rows.append({"method": r["method"], "phi_deg": math.degrees(phi), "sigma": sigma,
                                 "D": d, "rule": r.get("sigma_rule") or ""})
        except OSError as e:
            sys.exit(f"sigma_bins.py: {path}: {e.strerror}")
    return rows


def cell(rows):
    if not rows:
        return None
    covered = sum(r["phi_deg"] <= 2.0 * r["sigma"] for r in rows)
    good = [r for r in rows if r["phi_deg"] <= 2.0]
    ratio = statistics.median(r["sigma"] / max(r["phi_deg"], PHI_FLOOR_DEG) for r in rows)
    rules = {k: sum(r["rule"] == name for r in rows)
             for k, name in (("d", "disagreement"), ("b", "behind_camera"), ("n", "ambiguous_nullspace"),
                             ("a", "accelerometer_refused"))}
    return {"ok": len(rows), "coverage": covered / len(rows),
            "sharp": (sum(r["sigma"] <= 5.0 for r in good) / len(good)) if good else float("nan"),
            "good": len(good), "ratio": ratio, "sigma": statistics.median(r["sigma"] for r in rows),
            "rules": " ".join(f"{k}{v}" for k, v in rules.items() if v) or "-"}


def table(rows):
    print("| method | D [px] | ok | coverage | sharp (of phi <= 2 deg) | median sigma/phi | median sigma_deg | raised by |")
    print("|---|---|---|---|---|---|---|---|")
    for m in METHODS:
        mine = [r for r in rows if r["method"] == m]
        if not mine:
            continue
        for name, lo, hi in BINS:
            c = cell([r for r in mine if lo <= r["D"] < hi] if name != "all" else mine)
            if c is None:
                continue
            sharp = "-" if math.isnan(c["sharp"]) else f"{c['sharp']:.2f} ({c['good']})"
            print(f"| {m} | {name} | {c['ok']} | {c['coverage']:.2f} | {sharp} | {c['ratio']:.2f} | "
                  f"{c['sigma']:.3g} | {c['rules']} |")


def compact(rows, label, header):
    if header:
        print("| windows | method | ok | coverage D < 15 px | 15-25 px | >= 25 px | all | sharp | median sigma/phi |")
        print("|---|---|---|---|---|---|---|---|---|")
    for m in METHODS:
        mine = [r for r in rows if r["method"] == m]
        if not mine:
            continue
        cov = []
        for name, lo, hi in BINS:
            c = cell([r for r in mine if lo <= r["D"] < hi] if name != "all" else mine)
            cov.append("-" if c is None else f"{c['coverage']:.2f} ({c['ok']})")
        c = cell(mine)
        sharp = "-" if math.isnan(c["sharp"]) else f"{c['sharp']:.2f} ({c['good']})"
        print(f"| {label} | {m} | {c['ok']} | " + " | ".join(cov) + f" | {sharp} | {c['ratio']:.2f} |")


def plot(rows, out, title):
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        sys.exit("sigma_bins.py: --plot needs python3-matplotlib")
    methods = [m for m in METHODS if any(r["method"] == m for r in rows)]
    fig, axes = plt.subplots(1, len(methods), figsize=(3.2 * len(methods), 3.4), sharex=True, sharey=True,
                             squeeze=False)
    for ax, m in zip(axes[0], methods):
        mine = [r for r in rows if r["method"] == m and math.isfinite(r["sigma"])]
        for (name, lo, hi), colour in zip(BINS[:3], ("C3", "C1", "C2")):
            sel = [r for r in mine if lo <= r["D"] < hi]
            ax.scatter([r["sigma"] for r in sel], [max(r["phi_deg"], PHI_FLOOR_DEG) for r in sel], s=9,
                       color=colour, label=f"D {name} px")
        ax.plot([1e-2, 1e3], [1e-2, 1e3], "k-", lw=0.8, label="phi = sigma")
        ax.plot([1e-2, 1e3], [2e-2, 2e3], "k--", lw=0.8, label="phi = 2 sigma")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlim(0.1, 200)
        ax.set_ylim(PHI_FLOOR_DEG, 200)
        ax.set_title(m)
        ax.set_xlabel("sigma_deg [deg]")
    axes[0][0].set_ylabel("phi [deg]")
    axes[0][0].legend(fontsize=7, loc="upper left")
    if title:
        fig.suptitle(title, fontsize=9)
    fig.tight_layout()
    fig.savefig(out, dpi=110)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("csv", nargs="+")
    ap.add_argument("--plot", help="reliability plot PNG")
    ap.add_argument("--title", default="")
    ap.add_argument("--compact", metavar="LABEL")
    ap.add_argument("--header", action="store_true")
    a = ap.parse_args()
    rows = read_rows(a.csv)
    if not rows:
        sys.exit("sigma_bins.py: no ok rows with ground truth and sigma_deg")
    if a.compact:
        compact(rows, a.compact, a.header)
    else:
        table(rows)
    if a.plot:
        plot(rows, a.plot, a.title)


if __name__ == "__main__":
    main()
