#!/usr/bin/env python3
"""Plots of `celc simulate --study peers` (OUTDIR/peers.csv).

usage: plot_peers.py OUTDIR

Writes
  OUTDIR/peers_grid.png      median sign-agnostic phi [deg] against sigma, one
                             panel per speed (parallax ratio), every method,
                             with the CRLB (RMS) as a dashed line;
  OUTDIR/peers_ratio.png     RMS / CRLB per method over the V x sigma grid;
  OUTDIR/peers_factors.png   median phi against each one-factor sweep
                             (angular-velocity error, lines, events, outliers);
  OUTDIR/peers_table.md      the study table (rows: cells; per method median
                             sign-agnostic phi [deg], RMS / CRLB, median time [us]).
Needs python3-matplotlib.
"""
import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

STYLE = {"celc": ("C0", "CELC"), "celc_opt": ("C1", "CELC+opt"),
         "celc_ml": ("C2", "CELC+ML (lines refined)"), "ce3lc": ("C3", "CE3LC"),
         "npt": ("C4", "N-point (CVPR'24)"), "celc_acc": ("C5", "CELC+ML, constant acceleration")}


def num(x):
    return float(x) if x not in ("", None) else float("nan")


def read(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def methods(rows):
    seen = []
    for r in rows:
        if r["method"] not in seen:
            seen.append(r["method"])
    return seen


def in_group(r, g):
    return g in r["groups"].split(";")


def plot_grid(outdir, rows):
    grid = [r for r in rows if in_group(r, "grid")]
    speeds = sorted({num(r["speed_m_s"]) for r in grid})
    if not speeds:
        return
    fig, axes = plt.subplots(1, len(speeds), figsize=(3.6 * len(speeds), 3.6), squeeze=False)
    for ax, v in zip(axes[0], speeds):
        cell = [r for r in grid if num(r["speed_m_s"]) == v]
        for m in methods(cell):
            rs = sorted([r for r in cell if r["method"] == m], key=lambda r: num(r["sigma_px"]))
            color, label = STYLE.get(m, (None, m))
            ax.plot([num(r["sigma_px"]) for r in rs], [num(r["phi_median_agn_deg"]) for r in rs],
                    marker="o", ms=3, color=color, label=label)
        rs = sorted([r for r in cell if r["method"] == cell[0]["method"]],
                    key=lambda r: num(r["sigma_px"]))
        ax.plot([num(r["sigma_px"]) for r in rs], [num(r["crlb_rms_deg"]) for r in rs], "k--",
                label="CRLB (RMS over trials)")
        ax.plot([num(r["sigma_px"]) for r in rs], [num(r["crlb_median_deg"]) for r in rs], "k:",
                label="CRLB (median over trials)")
        ax.set_title("V = %g m/s (parallax %.3g)" % (v, num(cell[0]["parallax_ratio"])))
        ax.set_xlabel("pixel noise sigma [px]")
        ax.set_yscale("symlog", linthresh=0.1)
        ax.grid(alpha=0.3)
    axes[0][0].set_ylabel("median phi, sign-agnostic [deg]")
    axes[0][-1].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(outdir, "peers_grid.png"), dpi=120)
    plt.close(fig)

    fig, ax = plt.subplots(figsize=(8, 3.8))
    cells = sorted({(num(r["speed_m_s"]), num(r["sigma_px"])) for r in grid if num(r["sigma_px"]) > 0})
    ms = methods(grid)
    width = 0.8 / max(1, len(ms))
    for i, m in enumerate(ms):
        ys = []
        for (v, s) in cells:
            rr = [r for r in grid if r["method"] == m and num(r["speed_m_s"]) == v and num(r["sigma_px"]) == s]
            ys.append(num(rr[0]["rms_over_crlb"]) if rr else float("nan"))
        color, label = STYLE.get(m, (None, m))
        ax.bar([k + i * width for k in range(len(cells))], ys, width, color=color, label=label)
    ax.axhline(1.3, color="k", ls=":", lw=1, label="1.3 x bound")
    ax.set_xticks([k + 0.4 - width / 2 for k in range(len(cells))])
    ax.set_xticklabels(["V%g\ns%g" % c for c in cells], fontsize=7)
    ax.set_yscale("log")
    ax.set_ylabel("RMS phi / CRLB")
    ax.grid(alpha=0.3, axis="y")
    ax.legend(fontsize=7, ncol=3)
    fig.tight_layout()
    fig.savefig(os.path.join(outdir, "peers_ratio.png"), dpi=120)
    plt.close(fig)


def plot_factors(outdir, rows):
    sweeps = [("omega", "omega_error_deg_s", "angular-velocity error [deg/s]"),
              ("lines", "lines", "number of lines"),
              ("events", "events_per_line", "events per line"),
              ("outliers", "outliers", "outlier share")]
    fig, axes = plt.subplots(1, len(sweeps), figsize=(3.6 * len(sweeps), 3.6))
    for ax, (g, col, label) in zip(axes, sweeps):
        cell = [r for r in rows if in_group(r, g)]
        for m in methods(cell):
            rs = sorted([r for r in cell if r["method"] == m], key=lambda r: num(r[col]))
            color, lab = STYLE.get(m, (None, m))
            ax.plot([num(r[col]) for r in rs], [num(r["phi_median_agn_deg"]) for r in rs],
                    marker="o", ms=3, color=color, label=lab)
        if cell:
            rs = sorted([r for r in cell if r["method"] == cell[0]["method"]], key=lambda r: num(r[col]))
            ax.plot([num(r[col]) for r in rs], [num(r["crlb_rms_deg"]) for r in rs], "k--",
                    label="CRLB (RMS)")
        ax.set_xlabel(label)
        ax.set_yscale("log")
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("median phi, sign-agnostic [deg]")
    axes[-1].legend(fontsize=7)
    fig.suptitle("One factor at a time around 5 lines x 200 events, V = 2 m/s, sigma = 1 px",
                 fontsize=9)
    fig.tight_layout()
    fig.savefig(os.path.join(outdir, "peers_factors.png"), dpi=120)
    plt.close(fig)


def write_table(outdir, rows):
    ms = methods(rows)
    cells = []
    for r in rows:
        key = (r["groups"], r["speed_m_s"], r["sigma_px"], r["omega_error_deg_s"], r["lines"],
               r["events_per_line"], r["outliers"])
        if key not in [c[0] for c in cells]:
            cells.append((key, r))
    out = ["| cells | V [m/s] (parallax) | sigma [px] | w err [deg/s] | lines | events/line | outliers "
           "| CRLB RMS / median [deg] | " + " | ".join(ms) + " |",
           "|---" * (8 + len(ms)) + "|"]
    for key, first in cells:
        line = "| %s | %s (%.3g) | %s | %s | %s | %s | %s | %s" % (
            key[0].replace(";", ", "), key[1], num(first["parallax_ratio"]), key[2], key[3], key[4],
            key[5], key[6], ("%.3g / %.3g" % (num(first["crlb_rms_deg"]), num(first["crlb_median_deg"])))
            if first["crlb_rms_deg"] else "-")
        for m in ms:
            rr = [r for r in rows if r["method"] == m and (r["groups"], r["speed_m_s"], r["sigma_px"],
                  r["omega_error_deg_s"], r["lines"], r["events_per_line"], r["outliers"]) == key]
            if not rr or not rr[0]["phi_median_agn_deg"]:
                line += " | -"
                continue
            r = rr[0]
            ratio = ("%.2f" % num(r["rms_over_crlb"])) if r["rms_over_crlb"] else "-"
            line += " | %.3g / %s / %.0f" % (num(r["phi_median_agn_deg"]), ratio, num(r["time_median_us"]))
        out.append(line + " |")
    with open(os.path.join(outdir, "peers_table.md"), "w") as f:
        f.write("\n".join(out) + "\n")


def main():
    if len(sys.argv) != 2:
        sys.exit("usage: plot_peers.py OUTDIR")
    path = os.path.join(sys.argv[1], "peers.csv")
    if not os.path.exists(path):
        sys.exit(path + ": not found")
    rows = read(path)
    plot_grid(sys.argv[1], rows)
    plot_factors(sys.argv[1], rows)
    write_table(sys.argv[1], rows)


if __name__ == "__main__":
    main()
