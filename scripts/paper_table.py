#!/usr/bin/env python3
"""The simulation study in the paper's terms, as a Markdown table.

usage: paper_table.py SIMDIR COMMAND

Reads SIMDIR/<sweep>.csv (`celc simulate --sweep all`) and prints, per sweep
and level, the mean eps (unit-vector distance, 0 to 2) and the mean phi [rad]
over the ok trials of the paper's three methods (CELC, CELC+opt, CE3LC),
then celc_ml's mean phi. COMMAND is the command named above the table.
"""
import csv
import os
import sys

SWEEPS = [("default", "default setting", "-"),
          ("event_noise", "event noise", "px"),
          ("line_noise", "line end-point noise", "px"),
          ("omega_noise", "angular velocity noise", "rad/s"),
          ("speed", "speed", "m/s"),
          ("interval", "time interval", "s"),
          ("lines", "number of lines", "-")]
PAPER = ["celc", "celc_opt", "ce3lc"]


def cell(row, key):
    if row is None or not row.get(key + "_mean"):
        return "-"
    return "%.3f" % float(row[key + "_mean"])


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    simdir, command = sys.argv[1], sys.argv[2]
    print("Regenerate: `%s`" % command)
    print()
    print("| sweep | level | CELC eps | CELC phi [rad] | CELC+opt eps | CELC+opt phi [rad] "
          "| CE3LC eps | CE3LC phi [rad] | CELC+ML phi [rad] |")
    print("|---|---|---|---|---|---|---|---|---|")
    for sweep, name, unit in SWEEPS:
        path = os.path.join(simdir, sweep + ".csv")
        if not os.path.exists(path):
            continue
        rows = {}
        with open(path, newline="") as f:
            for r in csv.DictReader(f):
                rows.setdefault(r["level"], {})[r["method"]] = r
        for level in sorted(rows, key=float):
            by = rows[level]
            cells = []
            for m in PAPER:
                cells += [cell(by.get(m), "eps"), cell(by.get(m), "phi")]
            cells.append(cell(by.get("celc_ml"), "phi"))
            label = name if unit == "-" else "%s [%s]" % (name, unit)
            print("| %s | %s | %s |" % (label, "%g" % float(level), " | ".join(cells)))
    print()
    print("eps = |v_gt - v| between unit vectors (0 to 2, no unit); phi = acos(v_gt . v) [rad]; "
          "means over the trials whose status is ok.")


if __name__ == "__main__":
    main()
