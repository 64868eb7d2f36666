#!/usr/bin/env python3
"""Where a run's impure clusters get their foreign events from, window by window.

usage: impurity_sources.py RUNDIR SEQDIR [--corner-m 0.05] [--parallel-deg 10]

RUNDIR is a `celc run SEQDIR -o RUNDIR --dump-windows RUNDIR/windows` of a
`celc synth` sequence (SEQDIR holds events.txt, labels.txt and edges.txt,
the true 3D edges). A clustered event is foreign to its cluster when it is
noise or of another edge than the cluster's majority edge, so the foreign
share is 1 - purity. Each foreign edge event is put in one of three kinds
by the two 3D edges (the cluster's majority edge and its own):
  corner     the edges share an end point (within --corner-m metres): an
             edge grown round a corner into the next;
  crossing   apart in 3D and at least --parallel-deg apart in direction:
             edges that cross or touch in the image (another object's edge);
  parallel   apart and nearly parallel: neighbouring edges a few pixels apart.
It also counts the foreign edge events whose edge is the majority of a
cluster of its own (the clustering found that edge, and a better division
of the events could give them back). Prints a Markdown table, one row per
window, and the totals. Needs Debian's python3 only.
"""
import argparse
import csv
import glob
import math
import os
from collections import Counter, defaultdict

from cluster_variants import edge_labels


def read_edges(seq):
    """edge id -> (end point a, end point b), from edges.txt (id ax ay az bx by bz, metres)."""
    edges = {}
    with open(os.path.join(seq, "edges.txt")) as f:
        for number, line in enumerate(f, 1):
            fields = line.split()
            if not fields:
                continue
            if len(fields) != 7:
                raise SystemExit(f"{seq}/edges.txt:{number}: expected 7 fields, got {len(fields)}")
            values = [float(x) for x in fields[1:]]
            edges[int(fields[0])] = (values[:3], values[3:])
    return edges


def direction_angle_deg(e1, e2):
    """Angle between two 3D edges' directions [deg], in [0, 90]."""
    u = [b - a for a, b in zip(*e1)]
    v = [b - a for a, b in zip(*e2)]
    nu = math.sqrt(sum(x * x for x in u))
    nv = math.sqrt(sum(x * x for x in v))
    if nu == 0.0 or nv == 0.0:
        return 90.0
    cosine = abs(sum(x * y for x, y in zip(u, v))) / (nu * nv)
    return math.degrees(math.acos(min(1.0, cosine)))


def nearest_ends_m(e1, e2):
    """The smallest distance between an end point of one edge and one of the other [m]."""
    return min(math.dist(p, q) for p in e1 for q in e2)


def kind(edges, majority, other, corner_m, parallel_deg):
    if majority not in edges or other not in edges:
        return "crossing"  # an edge without geometry: counted with the edges apart
    if nearest_ends_m(edges[majority], edges[other]) <= corner_m:
        return "corner"
    return "parallel" if direction_angle_deg(edges[majority], edges[other]) < parallel_deg else "crossing"


def window_sources(cluster, edge, edges, corner_m, parallel_deg):
    """Counts of one window: clustered events, noise and foreign edge events by kind, and those found."""
    counts = defaultdict(Counter)
    for c, e in zip(cluster, edge):
        if c >= 0:
            counts[c][e] += 1
    majority = {}
    for c, by_edge in counts.items():
        real = [(n, e) for e, n in by_edge.items() if e >= 0]
        majority[c] = max(real)[1] if real else -1
    found_edges = {e for e in majority.values() if e >= 0}
    out = Counter()
    for c, by_edge in counts.items():
        for e, n in by_edge.items():
            out["clustered"] += n
            if e == majority[c]:
                continue
            if e < 0:
                out["noise"] += n
                continue
            out["foreign"] += n
            out[kind(edges, majority[c], e, corner_m, parallel_deg)] += n
            if e in found_edges:
                out["found"] += n
    return out


def share(part, whole):
    return f"{part / whole:.3f}" if whole else "-"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("rundir")
    ap.add_argument("seqdir")
    ap.add_argument("--corner-m", type=float, default=0.05, help="end points this close share a corner [m]")
    ap.add_argument("--parallel-deg", type=float, default=10.0, help="edges closer in direction are parallel [deg]")
    a = ap.parse_args()
    dump = os.path.join(os.path.abspath(a.rundir), "windows")
    tables = sorted(glob.glob(os.path.join(dump, "window_*[0-9].csv")))
    if not tables:
        raise SystemExit(f"{dump}: no window_NNNNN.csv (run celc run with --dump-windows RUNDIR/windows)")
    labels = edge_labels(a.seqdir)
    edges = read_edges(a.seqdir)
    print("| window | clustered events | purity | noise | foreign edge events | corner | crossing | parallel "
          "| of edges with a cluster of their own |")
    print("|---" * 9 + "|")
    total = Counter()
    for path in tables:
        w = int(os.path.basename(path)[len("window_"):-len(".csv")])
        with open(path, newline="") as f:
            reader = csv.reader(f)
            header = next(reader)
            if header[:4] != ["t", "x", "y", "cluster"]:
                raise SystemExit(f"{path}:1: expected the columns t,x,y,cluster")
            rows = list(reader)
        edge = [labels.get((round(float(r[0]) * 1e6), int(float(r[1])), int(float(r[2]))), -1) for r in rows]
        cluster = [int(r[3]) for r in rows]
        s = window_sources(cluster, edge, edges, a.corner_m, a.parallel_deg)
        total.update(s)
        n = s["clustered"]
        purity = share(n - s["noise"] - s["foreign"], n)
        print(f"| {w} | {n} | {purity} | {share(s['noise'], n)} | {share(s['foreign'], n)} | "
              f"{share(s['corner'], n)} | {share(s['crossing'], n)} | {share(s['parallel'], n)} | "
              f"{share(s['found'], s['foreign'])} |")
    n = total["clustered"]
    print()
    print(f"All windows: {n} clustered events, {share(total['noise'], n)} noise, "
          f"{share(total['foreign'], n)} of other edges (corner {share(total['corner'], n)}, "
          f"crossing {share(total['crossing'], n)}, parallel {share(total['parallel'], n)}); "
          f"{share(total['found'], total['foreign'])} of the foreign edge events are of edges with a cluster "
          f"of their own.")


if __name__ == "__main__":
    main()
