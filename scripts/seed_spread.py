#!/usr/bin/env python3
"""How much of the oracle-gap figures is the draw of a seed.

usage: seed_spread.py LABEL=RUNDIR,RUNDIR[,RUNDIR...] [LABEL=... ...] [--method celc_ml] [--spread-deg 2]

Each LABEL names a held-out set and lists its runs, one per seed, in the
order the table gives them (scripts/reproduce_results.sh seeds: the default
run, then cluster.seed 2 and 3). A RUNDIR holds one `celc run` folder per
`celc synth` sequence (RUNDIR/<name>/windows.csv with the truth columns).
Only the windows every run has, with an oracle in each, are compared. Per
set: the windows within the oracle gap (max(1.5x, +1 deg), as
cluster_quality.py) in each run, the median method phi in each run, the
windows whose method phi spans more than --spread-deg over the runs (a
refused window counts as 180 deg), and of those the ones within the gap in
some runs and beyond it in others.
"""
import argparse
import math
import os
import statistics
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from cluster_quality import oracle_windows, within_gap  # noqa: E402

REFUSED_DEG = 180.0


def read_run(rundir, method):
    """{(sequence, window): (method phi, oracle phi)} [rad] of the windows with an oracle."""
    refused = math.radians(REFUSED_DEG)
    return {(name, w): (phi if phi is not None else refused, oracle)
            for name, w, phi, oracle in oracle_windows(rundir, method, "seed_spread.py")}


def summarise(runs, spread_deg):
    """One table row's numbers for the runs of one set."""
    keys = sorted(set.intersection(*(set(r) for r in runs)))
    within = [sum(1 for k in keys if within_gap(*r[k])) for r in runs]
    medians = [math.degrees(statistics.median(r[k][0] for k in keys)) if keys else math.nan for r in runs]
    spread = flipped = 0
    for k in keys:
        phis = [math.degrees(r[k][0]) for r in runs]
        if max(phis) - min(phis) > spread_deg:
            spread += 1
            verdicts = {within_gap(*r[k]) for r in runs}
            flipped += 1 if len(verdicts) == 2 else 0
    return len(keys), within, medians, spread, flipped


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("sets", nargs="+", metavar="LABEL=RUNDIR,RUNDIR")
    ap.add_argument("--method", default="celc_ml")
    ap.add_argument("--spread-deg", type=float, default=2.0)
    a = ap.parse_args()
    rows = []
    for spec in a.sets:
        if "=" not in spec:
            raise SystemExit(f"seed_spread.py: expected LABEL=RUNDIR,RUNDIR, got {spec!r}")
        label, dirs = spec.split("=", 1)
        runs = [read_run(d, a.method) for d in dirs.split(",") if d]
        if len(runs) < 2:
            raise SystemExit(f"seed_spread.py: {label}: needs at least two runs")
        rows.append((label, *summarise(runs, a.spread_deg)))
    print(f"| set | windows | within the gap, run by run | median {a.method} phi [deg], run by run "
          f"| windows whose phi spans > {a.spread_deg:g} deg | ... within the gap in some runs only |")
    print("|---|---|---|---|---|---|")
    for label, n, within, medians, spread, flipped in rows:
        print(f"| {label} | {n} | {' / '.join(str(w) for w in within)} "
              f"| {' / '.join(f'{m:.2f}' for m in medians)} | {spread} | {flipped} |")


if __name__ == "__main__":
    main()
