#!/usr/bin/env python3
"""Where a window's gap to the oracle comes from: its clusters changed one way at a time.

usage: cluster_variants.py RUNDIR SEQDIR [--method celc_ml] [--windows 0,3] [--per-edge]

RUNDIR is a `celc run SEQDIR -o RUNDIR --dump-windows RUNDIR/windows` of a
`celc synth` sequence (SEQDIR holds events.txt and labels.txt). Each dumped
window is solved again by its own `celc solve` command (window_NNNNN.sh,
the run's options, gyro and seed) on five labellings of the same events:
  pipeline      the run's clusters, as dumped;
  pure          the run's clusters with every event not of the cluster's
                majority edge left out (impurity removed, fragments kept);
  joined        the run's clusters with the same majority edge joined
                (fragments joined, impurity kept);
  true_kept     the true edges, on the events the run clustered (fragments
                joined and impurity removed, the run's coverage kept);
  completed     the run's clusters, each unclustered event of an edge added
                to that edge's largest cluster among those it is the
                majority of (the left-out events of the edges found);
  true_found    the true edges on every event of the edges that are the
                majority of a cluster (the oracle without the edges the run
                did not find);
  true_all      the true edges on every edge event (the oracle's clusters).
Prints phi [deg] of the method for each labelling (the pipeline's is the
run's own, up to the undistortion table's rounding, which can tip a window
whose basins are tied: docs/running.md), the share of edge events the run
clustered, then how many windows each labelling puts within the oracle gap
(max(1.5x, +1 deg)), and of those beyond it with the pipeline's clusters,
how many each brings within it. With --per-edge, also each edge that is
the majority of several clusters on its own: the run's clusters with only
that edge's joined, which tells the edges whose fragments decide a window
(a window whose basins are tied tips on one edge). Needs Debian's python3
only.
"""
import argparse
import csv
import glob
import math
import os
import subprocess
import sys
import tempfile
from collections import Counter, defaultdict


def within_gap(phi, oracle):
    return phi <= max(1.5 * oracle, oracle + math.radians(1.0))


def angle(v, g):
    """Angle between two directions [rad], the sign included."""
    dot = sum(a * b for a, b in zip(v, g))
    n = math.sqrt(sum(a * a for a in v) * sum(b * b for b in g))
    return math.acos(max(-1.0, min(1.0, dot / n)))


def edge_labels(seq):
    """(t in microseconds, x, y) -> true edge, from events.txt and labels.txt."""
    out = {}
    with open(os.path.join(seq, "events.txt")) as fe, open(os.path.join(seq, "labels.txt")) as fl:
        for line, label in zip(fe, fl):
            t, x, y = line.split()[:3]
            out[(round(float(t) * 1e6), int(x), int(y))] = int(label)
    return out


def solve(script, csv_path, variant_path, method):
    """The method's unit velocity from the window's `celc solve` command on another labelling; None if refused."""
    command = open(script).read()
    quoted = [t for t in command.split() if t.startswith("'") and t.endswith("/" + os.path.basename(csv_path) + "'")]
    if len(quoted) != 1:
        raise SystemExit(f"{script}: does not name {os.path.basename(csv_path)} once")
    command = command.replace(quoted[0], "'" + variant_path + "'")
    with tempfile.NamedTemporaryFile("w", suffix=".sh", delete=False) as f:
        f.write(command)
    try:
        done = subprocess.run(["sh", f.name, "--methods", method], capture_output=True, text=True)
    finally:
        os.unlink(f.name)
    if done.returncode != 0:
        raise SystemExit(f"{script}: celc solve failed: {done.stderr.strip().splitlines()[-1:]}")
    for line in done.stdout.splitlines():
        fields = line.split(",")
        if fields[0] == method:
            return [float(x) for x in fields[2:5]] if fields[1] == "ok" else None
    return None


def solve_labelling(script, csv_path, header, events, labels, method, tmp, name):
    """The method's unit velocity on the window's events under `labels` (None if refused)."""
    path = os.path.join(tmp, f"{name}.csv")
    with open(path, "w") as f:
        f.write(",".join(header) + "\n")
        for ev, c in zip(events, labels):
            f.write(f"{ev[0]},{ev[1]},{ev[2]},{c}\n")
    return solve(script, csv_path, path, method)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("rundir")
    ap.add_argument("seqdir")
    ap.add_argument("--method", default="celc_ml")
    ap.add_argument("--windows", help="comma-separated window indices (default: every dumped window)")
    ap.add_argument("--per-edge", action="store_true",
                    help="also solve with one edge's clusters joined at a time (each edge with several)")
    a = ap.parse_args()
    dump = os.path.join(os.path.abspath(a.rundir), "windows")
    scripts = sorted(glob.glob(os.path.join(dump, "window_*.sh")))
    if not scripts:
        raise SystemExit(f"{dump}: no window_NNNNN.sh (run celc run with --dump-windows RUNDIR/windows)")
    rows = {}
    with open(os.path.join(a.rundir, "windows.csv"), newline="") as f:
        for r in csv.DictReader(f):
            if r["method"] == a.method:
                rows[int(r["window"])] = r
    wanted = {int(w) for w in a.windows.split(",")} if a.windows else None
    labels = edge_labels(a.seqdir)
    names = ["pipeline", "pure", "joined", "true_kept", "completed", "true_found", "true_all"]
    print(f"| window | run phi | oracle phi | " + " | ".join(names) + " | edge events clustered |")
    print("|---" * (len(names) + 4) + "|")
    beyond, within = Counter(), Counter()
    per_edge = []  # (window, edge, clusters, its events in them, phi, the run within the gap)
    n_beyond = n_windows = 0
    for script in scripts:
        w = int(os.path.basename(script)[len("window_"):-len(".sh")])
        r = rows.get(w)
        if (wanted is not None and w not in wanted) or r is None or r["gt_vx"] == "" or r["oracle_phi"] == "":
            continue
        gt = [float(r["gt_vx"]), float(r["gt_vy"]), float(r["gt_vz"])]
        csv_path = script[:-3] + ".csv"
        with open(csv_path, newline="") as f:
            reader = csv.reader(f)
            header = next(reader)
            events = [row for row in reader]
        edge = [labels.get((round(float(e[0]) * 1e6), int(float(e[1])), int(float(e[2]))), -1) for e in events]
        cluster = [int(e[3]) for e in events]
        counts = defaultdict(Counter)
        for c, e in zip(cluster, edge):
            if c >= 0:
                counts[c][e] += 1
        majority = {c: k.most_common(1)[0][0] for c, k in counts.items()}
        largest = {}  # edge -> its largest cluster among those it is the majority of
        for c, e in majority.items():
            if e >= 0 and (e not in largest or counts[c][e] > counts[largest[e]][e]):
                largest[e] = c
        variants = {
            "pipeline": cluster,
            "pure": [c if c >= 0 and e == majority[c] and e >= 0 else -1 for c, e in zip(cluster, edge)],
            "joined": [majority[c] if c >= 0 and majority[c] >= 0 else -1 for c in cluster],
            "true_kept": [e if c >= 0 and e >= 0 else -1 for c, e in zip(cluster, edge)],
            "completed": [c if c >= 0 else largest.get(e, -1) for c, e in zip(cluster, edge)],
            "true_found": [e if e in largest else -1 for e in edge],
            "true_all": [e if e >= 0 else -1 for e in edge],
        }
        n_edge = sum(1 for e in edge if e >= 0)
        kept = sum(1 for c, e in zip(cluster, edge) if c >= 0 and e >= 0)
        phis = {}
        run_phi = float(r["phi"]) if r["phi"] else math.pi
        oracle = float(r["oracle_phi"])
        with tempfile.TemporaryDirectory() as tmp:
            for name, cl in variants.items():
                v = solve_labelling(script, csv_path, header, events, cl, a.method, tmp, name)
                phis[name] = angle(v, gt) if v else math.pi
            if a.per_edge:
                of_edge = defaultdict(list)  # edge -> the clusters it is the majority of
                for c, e in sorted(majority.items()):
                    if e >= 0:
                        of_edge[e].append(c)
                for e, cs in sorted(of_edge.items()):
                    if len(cs) < 2:
                        continue
                    members = set(cs)
                    cl = [cs[0] if c in members else c for c in cluster]
                    v = solve_labelling(script, csv_path, header, events, cl, a.method, tmp, "edge")
                    per_edge.append((w, e, len(cs), sum(counts[c][e] for c in cs), angle(v, gt) if v else math.pi,
                                     within_gap(run_phi, oracle)))
        deg = lambda x: "%.2f" % math.degrees(x)
        print(f"| {w} | {deg(run_phi)} | {deg(oracle)} | " + " | ".join(deg(phis[n]) for n in names) +
              f" | {kept / n_edge if n_edge else math.nan:.2f} |")
        n_windows += 1
        for n in names:
            within[n] += within_gap(phis[n], oracle)
        if not within_gap(phis["pipeline"], oracle):
            n_beyond += 1
            for n in names[1:]:
                beyond[n] += within_gap(phis[n], oracle)
        sys.stdout.flush()
    print()
    print(f"Within the oracle gap, of {n_windows} windows: " + ", ".join(f"{n} {within[n]}" for n in names))
    print(f"Windows where the pipeline's clusters are beyond the oracle gap: {n_beyond}; brought within it by "
          + ", ".join(f"{n} {beyond[n]}" for n in names[1:]))
    if a.per_edge:
        oracle_of = {int(w): float(r["oracle_phi"]) for w, r in rows.items() if r["oracle_phi"]}
        print()
        print("One edge's clusters joined, the others as the run drew them:")
        print("| window | edge | its clusters | its events in them | phi [deg] | within the gap |")
        print("|---|---|---|---|---|---|")
        for w, e, n, events_in, phi, _ in per_edge:
            print(f"| {w} | {e} | {n} | {events_in} | {math.degrees(phi):.2f} | "
                  f"{'yes' if within_gap(phi, oracle_of[w]) else 'no'} |")
        beyond_windows = sorted({w for w, *_, run_within in per_edge if not run_within})
        brought = sorted({w for w, e, n, k, phi, run_within in per_edge
                          if not run_within and within_gap(phi, oracle_of[w])})
        print(f"Edges with several clusters: {len(per_edge)}; windows beyond the gap with such an edge: "
              f"{len(beyond_windows)}, brought within it by joining one edge's clusters: {len(brought)}"
              + (f" (windows {', '.join(map(str, brought))})" if brought else ""))


if __name__ == "__main__":
    main()
