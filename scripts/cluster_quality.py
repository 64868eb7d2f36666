#!/usr/bin/env python3
"""The clusters against the truth over runs of `celc synth` sequences.

usage: cluster_quality.py RUNDIR [--method celc_ml] [--scenes DIR]

RUNDIR holds one `celc run` output folder per sequence (RUNDIR/<name>/
windows.csv), run on sequences with labels.txt, so that windows.csv carries
the truth columns (purity, impure_clusters, edges, edges_complete, coverage,
noise_admitted, oracle_phi; docs/running.md). Prints one row per window,
then the targets: median event-weighted purity, the share of windows with
at most one cluster below 95% purity, the share of edges with 80% of their
events in one cluster, the median coverage, and the gap between the
method's phi on the pipeline's clusters and celc_ml's phi on the true
clusters of the same window (within max(1.5x, +1 deg)), and per sequence
where the oracle's median phi is at most 0.02 rad whether the method's
median phi is at most 0.05 rad (a refused window counts as pi in both
medians of the method).

With --scenes (the folder of the sequences, DIR/<name>/events.txt and
labels.txt), also the share of edges one of whose polarities holds 80% of
their events in the window. The others change polarity along them (a
chessboard's grid line); the growing keeps ON and OFF apart
(cluster.separate_polarity), so such an edge is complete only where the
fragment join (observations.merge_px) joins its ON and OFF clusters.
"""
import argparse
import csv
import glob
import math
import os
import statistics


def num(text):
    return float(text) if text not in ("", None) else math.nan


def within_gap(phi, oracle):
    """phi within max(1.5 x oracle, oracle + 1 deg) [rad]."""
    return phi <= max(1.5 * oracle, oracle + math.radians(1.0))


def oracle_windows(rundir, method, script):
    """(sequence, window, method phi or None when refused, oracle phi) [rad]
    of every window with an oracle in RUNDIR/<sequence>/windows.csv; exits
    with a one-line error naming `script` when there is none or a file lacks
    the truth columns."""
    files = sorted(glob.glob(os.path.join(rundir, "*", "windows.csv")))
    if not files:
        raise SystemExit(f"{script}: {rundir}: no <sequence>/windows.csv")
    out = []
    for path in files:
        name = os.path.basename(os.path.dirname(path))
        with open(path, newline="") as f:
            reader = csv.DictReader(f)
            if "oracle_phi" not in (reader.fieldnames or []):
                raise SystemExit(f"{script}: {path}: no oracle_phi column (a run without truth labels)")
            for r in reader:
                if r["method"] != method or r["oracle_phi"] in ("", None):
                    continue
                phi = float(r["phi"]) if r["status"] == "ok" and r["phi"] else None
                out.append((name, int(r["window"]), phi, float(r["oracle_phi"])))
    return out


def one_polarity_edges(seq_dir, spans, min_edge_events=20, share=0.8):
    """Per window span (t_start, t_end) [s]: (edges with at least
    min_edge_events events, of them those whose ON or OFF events are at least
    `share` of theirs), from the sequence's events.txt and labels.txt (the
    windows of cluster_quality.hpp: events with t_start <= t <= t_end)."""
    counts = [dict() for _ in spans]  # per window: edge -> [off, on]
    for name in ("events.txt", "labels.txt"):
        if not os.path.isfile(os.path.join(seq_dir, name)):
            raise SystemExit(f"{os.path.join(seq_dir, name)}: not found (--scenes names the sequences' folder)")
    with open(os.path.join(seq_dir, "events.txt")) as fe, open(os.path.join(seq_dir, "labels.txt")) as fl:
        for line, label in zip(fe, fl):
            edge = int(label)
            if edge < 0:
                continue
            t, _, _, p = line.split()[:4]
            t = float(t)
            for w, (t0, t1) in enumerate(spans):
                if t0 <= t <= t1:
                    c = counts[w].setdefault(edge, [0, 0])
                    c[1 if p == "1" else 0] += 1
    out = []
    for c in counts:
        sizes = [(off + on, max(off, on)) for off, on in c.values() if off + on >= min_edge_events]
        out.append((len(sizes), sum(1 for n, m in sizes if m >= share * n)))
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("rundir")
    ap.add_argument("--method", default="celc_ml", help="the pipeline's method compared with the oracle")
    ap.add_argument("--scenes", help="the sequences' folder: also the share of edges of one polarity")
    a = ap.parse_args()
    rows = []
    for path in sorted(glob.glob(os.path.join(a.rundir, "*", "windows.csv"))):
        name = os.path.basename(os.path.dirname(path))
        with open(path, newline="") as f:
            for r in csv.DictReader(f):
                if r["method"] != a.method:
                    continue
                if "purity" not in r:
                    raise SystemExit(f"{path}: no truth columns (a windows.csv of an older celc?)")
                if r["edges"] == "":
                    continue  # no truth for this window
                rows.append((name, r))
    if not rows:
        raise SystemExit(f"{a.rundir}: no windows with truth columns")
    print("| sequence | window | status | purity | impure clusters | edges complete | coverage | noise admitted "
          "| %s phi [deg] | oracle phi [deg] | within gap |" % a.method)
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    purity, coverage, impure_ok, gaps, phis, oracles = [], [], [], [], [], []
    per_sequence = {}  # name -> ([method phi], [oracle phi]) over windows with an oracle
    edges = edges_complete = 0
    for name, r in rows:
        p, cov, noise = num(r["purity"]), num(r["coverage"]), num(r["noise_admitted"])
        phi, oracle = num(r["phi"]), num(r["oracle_phi"])
        n_imp = int(num(r["impure_clusters"])) if r["impure_clusters"] else 0
        e, ec = int(num(r["edges"])), int(num(r["edges_complete"]))
        edges += e
        edges_complete += ec
        if not math.isnan(p):
            purity.append(p)
        if not math.isnan(cov):
            coverage.append(cov)
        impure_ok.append(n_imp <= 1)
        gap = ""
        if not math.isnan(oracle):
            ok = not math.isnan(phi) and within_gap(phi, oracle)
            gaps.append(ok)
            phis.append(math.pi if math.isnan(phi) else phi)
            oracles.append(oracle)
            seq_phis, seq_oracles = per_sequence.setdefault(name, ([], []))
            seq_phis.append(phis[-1])
            seq_oracles.append(oracle)
            gap = "yes" if ok else "no"
        deg = lambda x: "-" if math.isnan(x) else "%.1f" % math.degrees(x)
        f3 = lambda x: "-" if math.isnan(x) else "%.3f" % x
        print(f"| {name} | {r['window']} | {r['status']} | {f3(p)} | {n_imp} | {ec} / {e} | {f3(cov)} | {f3(noise)} "
              f"| {deg(phi)} | {deg(oracle)} | {gap} |")
    med = lambda x: statistics.median(x) if x else math.nan
    share = lambda x: sum(x) / len(x) if x else math.nan
    print()
    print("| target | measured | goal |")
    print("|---|---|---|")
    print(f"| event-weighted purity, median window | {med(purity):.3f} | >= 0.99 |")
    print(f"| windows with at most one cluster below 95% purity | {share(impure_ok):.2f} | >= 0.90 |")
    print(f"| edges with >= 80% of their events in one cluster | "
          f"{(edges_complete / edges if edges else math.nan):.2f} ({edges_complete} / {edges}) | >= 0.80 |")
    if a.scenes:
        one_polarity = counted = 0
        for name in sorted({n for n, _ in rows}):
            spans = [(num(r["t_start"]), num(r["t_end"])) for n, r in rows if n == name]
            for n_edges, n_one in one_polarity_edges(os.path.join(a.scenes, name), spans):
                counted += n_edges
                one_polarity += n_one
        if counted != edges:
            raise SystemExit(f"{a.scenes}: {counted} edges in the sequences' windows, {edges} in windows.csv")
        print(f"| edges with >= 80% of their events of one polarity (the others are complete only where "
              f"the fragment join joins their ON and OFF clusters) | "
              f"{one_polarity / edges if edges else math.nan:.2f} ({one_polarity} / {edges}) | |")
    print(f"| coverage of edge events, median window | {med(coverage):.3f} | >= 0.95 |")
    print(f"| windows where {a.method} is within max(1.5x, +1 deg) of the oracle | {share(gaps):.2f} "
          f"({sum(gaps)} / {len(gaps)}) | >= 0.80 |")
    mp, mo = med(phis), med(oracles)
    print(f"| median {a.method} phi against the median oracle phi [deg] | {math.degrees(mp):.2f} against "
          f"{math.degrees(mo):.2f} ({'within' if oracles and within_gap(mp, mo) else 'beyond'} max(1.5x, +1 deg)) "
          f"| within |")
    easy = [(n, med(p), med(o)) for n, (p, o) in sorted(per_sequence.items()) if med(o) <= 0.02]
    held = [n for n, p, o in easy if p <= 0.05]
    missed = ", ".join(f"{n} {math.degrees(p):.1f} deg" for n, p, o in easy if p > 0.05)
    print(f"| sequences whose oracle median is <= 0.02 rad with a median {a.method} phi <= 0.05 rad | "
          f"{len(held)} / {len(easy)}{' (missed: ' + missed + ')' if missed else ''} | all |")


if __name__ == "__main__":
    main()
