#!/usr/bin/env python3
"""Compares the windows.csv of two runs, cell by cell, except the runtime_ms column.

usage: same_windows.py A B [A2 B2 ...]
A and B are windows.csv files or the run folders holding them. Prints one line
per pair ("same: N rows" or the first differing rows) and exits 1 when any pair
differs: two builds (or two thread counts) that must give the same estimates
for a fixed seed are checked with it.
"""
import csv
import os
import sys

IGNORED = {"runtime_ms"}


def rows(path):
    if os.path.isdir(path):
        path = os.path.join(path, "windows.csv")
    with open(path, newline="") as f:
        table = list(csv.reader(f))
    if not table:
        return path, [], []
    header = table[0]
    keep = [i for i, name in enumerate(header) if name not in IGNORED]
    return path, [header[i] for i in keep], [[r[i] if i < len(r) else "" for i in keep] for r in table[1:]]


def compare(a, b):
    pa, ha, ra = rows(a)
    pb, hb, rb = rows(b)
    if ha != hb:
        return ["%s, %s: different columns" % (pa, pb)]
    out = []
    if len(ra) != len(rb):
        out.append("%s, %s: %d and %d rows" % (pa, pb, len(ra), len(rb)))
    for k, (x, y) in enumerate(zip(ra, rb)):
        if x != y:
            cols = [ha[i] for i in range(len(x)) if x[i] != y[i]]
            out.append("%s, %s: row %d differs in %s" % (pa, pb, k + 1, ", ".join(cols)))
            if len(out) >= 5:
                break
    return out


def main(argv):
    if len(argv) < 3 or len(argv) % 2 == 0:
        print(__doc__.strip(), file=sys.stderr)
        return 2
    bad = False
    for a, b in zip(argv[1::2], argv[2::2]):
        diffs = compare(a, b)
        if diffs:
            bad = True
            print("\n".join(diffs))
        else:
            print("same: %s, %s (%d rows; runtime_ms aside)" % (a, b, len(rows(a)[2])))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
