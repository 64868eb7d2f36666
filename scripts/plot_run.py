#!/usr/bin/env python3
"""Plots of `celc run` results (OUTDIR/windows.csv).

usage: plot_run.py OUTDIR [OUTDIR ...]
       plot_run.py --table OUT.png [--max-sigma DEG] --run LABEL CSV [CSV ...] [--run ...]

Per OUTDIR it writes
  OUTDIR/velocity.png  one column per method, rows the x, y, z components of
                       the estimated unit direction against the window
                       mid-time [s] after the first window's start (ok windows
                       as points and lines, the others as x on the lower
                       edge), the ground truth dashed black, and a band of
                       +-sin(sigma_deg) around each component (clipped to
                       [-1, 1]) where windows.csv has sigma_deg; an open
                       square marks celc_acc's windows answered with the
                       acceleration model (column model);
  OUTDIR/error.png     phi [deg] per window and method (log axis), the median
                       per method in the legend; only with ground truth (else
                       no error.png, and an old one is removed).
With --table it writes OUT.png: several runs side by side, per run a box plot
of phi [deg] per method (top) and the share of ok windows per method (bottom).
Each --run is one run (its CSVs merge: shards). --max-sigma DEG keeps only ok
windows with sigma_deg <= DEG. Needs python3-matplotlib; errors are one line
on stderr and exit status 1.
"""
import argparse
import csv
import math
import os
import statistics
import sys

STYLE = {"celc": ("C0", "CELC"), "celc_opt": ("C1", "CELC+opt"),
         "celc_ml": ("C2", "CELC+ML (lines refined)"), "ce3lc": ("C3", "CE3LC"),
         "npt": ("C4", "N-point (CVPR'24)"), "celc_acc": ("C5", "CELC+ML, constant acceleration")}
PHI_FLOOR_DEG = 1e-3  # phi below this [deg] is drawn at it (log axis)


def num(x):
    try:
        return float(x) if x not in ("", None) else float("nan")
    except ValueError:
        return float("nan")


def style(method):
    return STYLE.get(method, (None, method))


def read_rows(paths):
    """Rows of one run (several CSVs: shards); a (window, method) seen twice counts once."""
    rows, seen = [], set()
    for path in paths:
        with open(path, newline="") as f:
            for r in csv.DictReader(f):
                key = (r.get("window"), r.get("method"))
                if None in key or key in seen or not key[0].isdigit():
                    continue  # a torn last line of an interrupted run, or a repeat
                seen.add(key)
                rows.append(r)
    rows.sort(key=lambda r: (int(r["window"]), r["method"]))
    return rows


def methods_of(rows):
    order = list(STYLE)
    found = {r["method"] for r in rows}
    return [m for m in order if m in found] + sorted(found - set(order))


def has_gt(r):
    return all(math.isfinite(num(r.get(k))) for k in ("gt_vx", "gt_vy", "gt_vz"))


def is_ok(r):
    return r.get("status") == "ok" and all(math.isfinite(num(r.get(k))) for k in ("vx", "vy", "vz"))


def phi_deg(r):
    p = num(r.get("phi"))
    return max(math.degrees(p), PHI_FLOOR_DEG) if math.isfinite(p) else float("nan")


def log_axis_deg(plt, ax):
    """A log y axis [deg] labelled at 1, 2, 5 times powers of ten."""
    import matplotlib.ticker as ticker
    ax.set_yscale("log")
    ax.yaxis.set_major_locator(ticker.LogLocator(base=10.0, subs=(1.0, 2.0, 5.0)))
    ax.yaxis.set_major_formatter(plt.FuncFormatter(lambda y, _: "%g" % y))
    ax.yaxis.set_minor_formatter(ticker.NullFormatter())


def save(fig, path):
    tmp = path + ".tmp.png"
    fig.savefig(tmp, dpi=110)
    os.replace(tmp, path)


def time_origin(rows):
    """The first window's t_start [s]: plots count time from it (recordings' clocks start anywhere)."""
    ts = [num(r["t_start"]) for r in rows if math.isfinite(num(r["t_start"]))]
    return min(ts) if ts else 0.0


def time_label(rows):
    return "window mid-time [s] after t0 = %.6f s" % time_origin(rows)


def windows_of(rows):
    """window -> (mid-time [s] after time_origin, ground truth (x, y, z) or None)."""
    out = {}
    t0 = time_origin(rows)
    for r in rows:
        w = int(r["window"])
        t = 0.5 * (num(r["t_start"]) + num(r["t_end"])) - t0
        gt = (num(r["gt_vx"]), num(r["gt_vy"]), num(r["gt_vz"])) if has_gt(r) else None
        if w not in out or (out[w][1] is None and gt is not None):
            out[w] = (t, gt)
    return out


def sigma_band(y, sigma_deg):
    """(low, high) of a component y with sigma_deg [deg]: y +- sin(sigma), clipped to [-1, 1]."""
    if math.isnan(sigma_deg) or math.isnan(y):
        return float("nan"), float("nan")
    d = 1.0 if (math.isinf(sigma_deg) or sigma_deg >= 90.0) else math.sin(math.radians(sigma_deg))
    return max(-1.0, y - d), min(1.0, y + d)


def plot_velocity(plt, outdir, name, rows):
    """Rows: the components x, y, z; columns: the methods (each with its own band)."""
    wins = windows_of(rows)
    order = sorted(wins)
    times = [wins[w][0] for w in order]
    with_gt = any(wins[w][1] is not None for w in order)
    ms = 2 if len(order) > 60 else 4
    methods = methods_of(rows)
    ncol = len(methods)
    fig, axes = plt.subplots(3, ncol, figsize=(min(20.0, 2.0 + 3.6 * ncol), 7.6), sharex=True,
                             sharey=True, squeeze=False)
    for j, m in enumerate(methods):
        color, label = style(m)
        by_w = {int(r["window"]): r for r in rows if r["method"] == m}
        ok = [w for w in order if w in by_w and is_ok(by_w[w])]
        sig = sorted(num(by_w[w].get("sigma_deg")) for w in ok if not math.isnan(num(by_w[w].get("sigma_deg"))))
        title = "%s\nok %d of %d windows" % (label, len(ok), len(order))
        n_acc = sum(1 for w in ok if by_w[w].get("model") == "acceleration")
        if m == "celc_acc":
            title += ", %d with acceleration" % n_acc
        if sig:
            title += ", median sigma %.3g deg" % statistics.median(sig)
        failed = {}
        for w in order:
            if w not in ok:
                st = (by_w[w].get("reason") or by_w[w].get("status")) if w in by_w else "no row"
                failed[st] = failed.get(st, 0) + 1
        if failed:
            top = sorted(failed.items(), key=lambda kv: -kv[1])[:2]
            title += "\nnot ok: " + ", ".join("%s %d" % kv for kv in top) + (", ..." if len(failed) > 2 else "")
        bad_t = [t for w, t in zip(order, times) if w not in ok]
        axes[0][j].set_title(title, fontsize=9, color=color)
        for k, key in enumerate(("vx", "vy", "vz")):
            ax = axes[k][j]
            # NaN where not ok: the line breaks there, the markers show the ok windows.
            ys = [num(by_w[w][key]) if w in by_w and is_ok(by_w[w]) else float("nan") for w in order]
            ax.plot(times, ys, color=color, lw=1.0, marker="o", ms=ms, zorder=4)
            # celc_acc's windows answered with the acceleration model: an open square.
            acc_t = [t for w, t in zip(order, times) if w in by_w and by_w[w].get("model") == "acceleration"]
            if acc_t:
                ax.plot(acc_t, [num(by_w[w][key]) for w in order if w in by_w
                                and by_w[w].get("model") == "acceleration"], "s", mfc="none",
                        mec="k", ms=ms + 4, mew=1.0, zorder=6)
            band = [sigma_band(y, num(by_w[w].get("sigma_deg")) if w in by_w else float("nan"))
                    for w, y in zip(order, ys)]
            if any(not math.isnan(lo) for lo, _ in band):
                ax.fill_between(times, [lo for lo, _ in band], [hi for _, hi in band], color=color,
                                alpha=0.22, lw=0, zorder=2)
            if with_gt:
                g = [wins[w][1][k] if wins[w][1] is not None else float("nan") for w in order]
                ax.plot(times, g, color="k", lw=1.4, ls="--", zorder=5)
            if bad_t:  # the windows that are not ok, on the lower edge
                ax.plot(bad_t, [-1.04] * len(bad_t), "x", color="0.45", ms=ms, zorder=3, clip_on=False)
            ax.axhline(0.0, color="0.6", lw=0.6, zorder=0)
            ax.grid(alpha=0.3)
            if j == 0:
                ax.set_ylabel("v_%s (unit direction)" % "xyz"[k])
        axes[-1][j].set_xlabel(time_label(rows) if ncol < 3 else "window mid-time [s] after t0")
        axes[-1][j].xaxis.set_major_locator(plt.MaxNLocator(4))
    axes[0][0].set_ylim(-1.08, 1.08)
    pad = 0.02 * (times[-1] - times[0]) if len(times) > 1 else 0.01
    axes[0][0].set_xlim(times[0] - pad, times[-1] + pad)
    handles = [plt.Line2D([], [], color="0.3", marker="o", ms=4, lw=1.0),
               plt.Line2D([], [], color="0.45", marker="x", ms=4, lw=0),
               plt.Rectangle((0, 0), 1, 1, color="0.3", alpha=0.22)]
    labels = ["estimate (ok windows)", "window not ok",
              "+-sin(sigma_deg) per component, clipped to [-1, 1]" if "sigma_deg" in rows[0]
              else "no sigma_deg (windows.csv of the first format)"]
    if any(r.get("model") == "acceleration" for r in rows):
        handles.append(plt.Line2D([], [], color="k", marker="s", mfc="none", ms=8, lw=0))
        labels.append("acceleration model chosen (celc_acc)")
    if with_gt:
        handles.append(plt.Line2D([], [], color="k", lw=1.4, ls="--"))
        labels.append("ground truth")
    rows_of_legend = 1 if len(handles) <= 4 else 2
    fig.legend(handles, labels, loc="lower center", ncol=-(-len(handles) // rows_of_legend), fontsize=9,
               frameon=False)
    fig.suptitle("celc run %s: velocity direction per window, camera frame, estimates as written "
                 "(a sign flip mirrors all three)%s; t0 = %.6f s"
                 % (name, "" if with_gt else "; no ground truth", time_origin(rows)), fontsize=10)
    fig.tight_layout(rect=(0, 0.045 * rows_of_legend, 1, 1))
    save(fig, os.path.join(outdir, "velocity.png"))
    plt.close(fig)


def plot_error(plt, outdir, name, rows):
    path = os.path.join(outdir, "error.png")
    if not any(math.isfinite(phi_deg(r)) for r in rows):
        if os.path.exists(path):
            os.remove(path)  # an older run's plot must not stand beside these rows
        return False
    wins = windows_of(rows)
    order = sorted(wins)
    times = [wins[w][0] for w in order]
    ms = 2 if len(order) > 60 else 4
    fig, ax = plt.subplots(figsize=(11, 4.2))
    for m in methods_of(rows):
        color, label = style(m)
        by_w = {int(r["window"]): r for r in rows if r["method"] == m}
        ys = [phi_deg(by_w[w]) if w in by_w else float("nan") for w in order]
        good = sorted(y for y in ys if math.isfinite(y))
        text = "median %.3g deg, %d windows" % (statistics.median(good), len(good)) if good else "no ok window"
        ax.plot(times, ys, color=color, lw=0.8 if len(order) > 60 else 1.0, marker="o", ms=ms,
                label="%s: %s" % (label, text))
    ax.axhline(90.0, color="0.4", lw=0.9, ls=":", label="90 deg: a random direction's median")
    log_axis_deg(plt, ax)
    ax.set_xlabel(time_label(rows))
    ax.set_ylabel("phi, angle to ground truth [deg]")
    ax.grid(alpha=0.3, which="both")
    ax.legend(loc="upper left", bbox_to_anchor=(1.005, 1.0), fontsize=8, framealpha=0.9)
    ax.set_title("celc run %s: error per window (ok windows with ground truth; a gap is a window "
                 "that is not ok)" % name, fontsize=10)
    fig.tight_layout()
    save(fig, path)
    plt.close(fig)
    return True


def plain(text):
    """TEXT shown as it is: matplotlib reads $...$ as mathematics."""
    return text.replace("$", r"\$")


def run_name(outdir):
    return plain(os.path.basename(os.path.normpath(os.path.abspath(outdir))))


def plot_outdir(plt, outdir):
    csv_path = os.path.join(outdir, "windows.csv")
    if not os.path.exists(csv_path):
        raise RuntimeError(csv_path + ": not found")
    rows = read_rows([csv_path])
    if not rows:
        raise RuntimeError(csv_path + ": no rows")
    name = run_name(outdir)
    plot_velocity(plt, outdir, name, rows)
    plot_error(plt, outdir, name, rows)


def plot_table(plt, out, runs, max_sigma):
    data = []  # (label, rows)
    for label, paths in runs:
        rows = read_rows(paths)
        if max_sigma is not None:
            for r in rows:
                if r.get("status") == "ok" and not num(r.get("sigma_deg")) <= max_sigma:
                    r["status"] = "sigma_above_max"
                    r["phi"] = ""
        data.append((plain(label), rows))
    ms = methods_of([r for _, rows in data for r in rows])
    n = len(data)
    width = 0.8 / max(1, len(ms))
    fig_w = min(22.0, max(8.0, 0.35 * n * len(ms) + 3.0))
    fig, (ax, bx) = plt.subplots(2, 1, figsize=(fig_w, 7.0), sharex=True,
                                 gridspec_kw={"height_ratios": [2.2, 1.0]})
    for i, m in enumerate(ms):
        color, label = style(m)
        pos = [k + (i - (len(ms) - 1) / 2.0) * width for k in range(n)]
        boxes, box_pos, share = [], [], []
        for k, (_, rows) in enumerate(data):
            mine = [r for r in rows if r["method"] == m]
            phis = [phi_deg(r) for r in mine if is_ok(r)]
            phis = [p for p in phis if math.isfinite(p)]
            if phis:
                boxes.append(phis)
                box_pos.append(pos[k])
            share.append(sum(1 for r in mine if is_ok(r)) / len(mine) if mine else float("nan"))
        if boxes:
            bp = ax.boxplot(boxes, positions=box_pos, widths=width * 0.85, patch_artist=True,
                            showfliers=max(len(b) for b in boxes) > 40, manage_ticks=False,
                            flierprops={"marker": ".", "markersize": 3, "markeredgecolor": color},
                            medianprops={"color": "k", "lw": 1.2})
            for b in bp["boxes"]:
                b.set_facecolor(color)
                b.set_alpha(0.75)
            for x, phis in zip(box_pos, boxes):
                if len(phis) <= 40:  # few windows: every one as a dot over its box
                    jitter = [x + width * 0.25 * ((j * 0.618) % 1.0 - 0.5) for j in range(len(phis))]
                    ax.plot(jitter, phis, ".", color="k", ms=3, alpha=0.6, zorder=4)
        bx.bar(pos, share, width, color=color, label=label)
    for k, (_, rows) in enumerate(data):
        if not any(math.isfinite(phi_deg(r)) for r in rows if is_ok(r)):
            ax.text(k, 0.5, "no ground truth", transform=ax.get_xaxis_transform(), ha="center",
                    va="center", fontsize=8, color="0.35", rotation=90 if n > 6 else 0)
    ax.axhline(90.0, color="0.4", lw=0.9, ls=":")
    for k in range(1, n):
        for a in (ax, bx):
            a.axvline(k - 0.5, color="0.75", lw=0.8)
    log_axis_deg(plt, ax)
    ax.set_ylabel("phi, angle to ground truth [deg]")
    ax.grid(alpha=0.3, which="both", axis="y")
    ax.set_xlim(-0.5, n - 0.5)
    handles = [plt.Rectangle((0, 0), 1, 1, color=style(m)[0], alpha=0.75) for m in ms]
    ax.legend(handles, [style(m)[1] for m in ms], loc="upper left", bbox_to_anchor=(1.005, 1.0),
              fontsize=8)
    title = ("celc table: phi per window and method\n(box: quartiles, whiskers 1.5 IQR, line: median, "
             "dots: windows; dotted: 90 deg)")
    if max_sigma is not None:
        title += "\nok windows with sigma_deg <= %g deg only" % max_sigma
    ax.set_title(title, fontsize=10)
    bx.set_ylim(0, 1.05)
    bx.set_ylabel("share of windows ok" if max_sigma is None else "share ok, sigma <= %g deg" % max_sigma)
    bx.grid(alpha=0.3, axis="y")
    bx.set_xticks(range(n))
    rotate = n > 4 or max(len(label) for label, _ in data) > 18
    counts = [len({r["window"] for r in rows}) for _, rows in data]
    bx.set_xticklabels(["%s\n%d windows" % (label, c) for (label, _), c in zip(data, counts)],
                       rotation=30 if rotate else 0,
                       ha="right" if rotate else "center", fontsize=9)
    fig.tight_layout()
    save(fig, out)
    plt.close(fig)


def main():
    if len(sys.argv) > 1 and sys.argv[1] == "--table":
        p = argparse.ArgumentParser(prog="plot_run.py --table")
        p.add_argument("--table", required=True)
        p.add_argument("--max-sigma", type=float, default=None)
        p.add_argument("--run", nargs="+", action="append", required=True, metavar="LABEL CSV")
        a = p.parse_args()
        runs = []
        for r in a.run:
            if len(r) < 2:
                raise RuntimeError("--run LABEL CSV [CSV ...]: no CSV for '%s'" % r[0])
            runs.append((r[0], r[1:]))
    elif len(sys.argv) >= 2 and not sys.argv[1].startswith("-"):
        a = None
    else:
        sys.exit(__doc__)
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError as e:
        raise RuntimeError("needs python3-matplotlib (%s)" % e)
    if a is not None:
        plot_table(plt, a.table, runs, a.max_sigma)
    else:
        errors = []
        for outdir in sys.argv[1:]:  # every folder, even after one that fails
            try:
                plot_outdir(plt, outdir)
            except Exception as e:
                errors.append(str(e))
        if errors:
            raise RuntimeError("; ".join(errors))


if __name__ == "__main__":
    try:
        main()
    except Exception as e:  # one line for celc's warning, no traceback
        print("plot_run.py: %s" % e, file=sys.stderr)
        sys.exit(1)
