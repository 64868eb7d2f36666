#!/usr/bin/env python3
"""Markdown plumbing of scripts/reproduce_results.sh.

usage:
  results_tables.py table N             stdin's N-th Markdown table (0-based), with the
                                        title line above it when there is one
  results_tables.py block PREFIX        the table that follows stdin's first line starting
                                        with PREFIX, with that line
  results_tables.py put FILE REGENERATE stdin (tables) into FILE under the line
                                        "Regenerate: REGENERATE", keeping FILE's legend
                                        (the text after its tables)
  results_tables.py windows CSV         a run's windows.csv as a table: per window and
                                        method the status, phi [rad], sigma_deg [deg], D [px]
  results_tables.py summary DIR         the README's results table from DIR's
                                        simulation_default.md, peers.md and scenes.md
  results_tables.py readme README FILE  README's table between the results markers
                                        replaced by FILE's content
  results_tables.py include PAGE...     in each page, every block between
                                        "<!-- include results/NAME.md -->" and
                                        "<!-- end include -->" replaced by that file's
                                        Regenerate line and tables (not its legend)
"""
import re
import sys

METHODS = ["celc", "celc_opt", "celc_ml", "ce3lc", "npt"]
BEGIN, END = "<!-- results table: begin -->", "<!-- results table: end -->"


def is_row(line):
    return line.lstrip().startswith("|")


def tables(lines):
    """(start, end) line ranges of the Markdown tables, a title line included."""
    out, i = [], 0
    while i < len(lines):
        if is_row(lines[i]) and i + 1 < len(lines) and re.match(r"^\s*\|[\s:|-]+\|\s*$", lines[i + 1]):
            start = i
            if i > 0 and lines[i - 1].strip() and not is_row(lines[i - 1]) \
                    and not lines[i - 1].startswith("Regenerate:"):
                start = i - 1
            while i < len(lines) and is_row(lines[i]):
                i += 1
            out.append((start, i))
        else:
            i += 1
    return out


def cmd_table(n):
    lines = sys.stdin.read().splitlines()
    s, e = tables(lines)[n]
    print("\n".join(lines[s:e]))


def cmd_block(prefix):
    lines = sys.stdin.read().splitlines()
    for i, line in enumerate(lines):
        if line.startswith(prefix):
            j = i + 1
            while j < len(lines) and not is_row(lines[j]):
                j += 1
            while j < len(lines) and is_row(lines[j]):
                j += 1
            print("\n".join(l for l in lines[i:j] if l.strip()))
            return
    sys.exit("results_tables.py: no line starting with %r" % prefix)


def cmd_put(path, regenerate):
    new = sys.stdin.read().strip("\n")
    legend = ""
    try:
        with open(path, encoding="utf-8") as f:
            old = f.read().splitlines()
        spans = tables(old)
        if spans:
            legend = "\n".join(old[spans[-1][1]:]).strip("\n")
    except FileNotFoundError:
        pass
    with open(path, "w", encoding="utf-8") as f:
        f.write("Regenerate: %s\n\n%s\n" % (regenerate, new))
        if legend:
            f.write("\n%s\n" % legend)


def rows_of(path):
    """{first cell: [cells]} of every table row of a file."""
    out = {}
    with open(path, encoding="utf-8") as f:
        for line in f:
            if is_row(line):
                cells = [c.strip() for c in line.strip().strip("|").split("|")]
                out.setdefault(cells[0].strip("`*"), cells)
    return out


def cmd_windows(path):
    import csv
    print("| window | t_start [s] | t_end [s] | method | status | phi [rad] | sigma_deg [deg] | translation_px [px] |")
    print("|---|---|---|---|---|---|---|---|")
    with open(path, newline="") as f:
        for r in csv.DictReader(f):
            phi = "%.3f" % float(r["phi"]) if r.get("phi") else "-"
            sigma = "%.1f" % float(r["sigma_deg"]) if r.get("sigma_deg") else "-"
            d = "%.1f" % float(r["translation_px"]) if r.get("translation_px") else "-"
            status = r["status"] + (" (%s)" % r["reason"] if r.get("reason") else "")
            print("| %s | %.3f | %.3f | %s | %s | %s | %s | %s |" % (
                r["window"], float(r["t_start"]), float(r["t_end"]), r["method"], status, phi, sigma, d))


def cmd_summary(d):
    sim = rows_of(d + "/simulation_default.md")
    peers_rows = []
    with open(d + "/peers.md", encoding="utf-8") as f:
        for line in f:
            if is_row(line):
                peers_rows.append([c.strip() for c in line.strip().strip("|").split("|")])
    header, base = peers_rows[0], next(r for r in peers_rows[2:] if r[0].startswith("base"))
    scenes = rows_of(d + "/scenes.md")
    print("| method | paper's scene, mean phi [rad] | peers, median phi [deg] (RMS / bound) "
          "| rendered, median phi [rad] | rendered, within 0.1 rad |")
    print("|---|---|---|---|---|")
    for m in METHODS:
        mean_phi = sim[m][3].split("+-")[0].strip()
        median, ratio = [x.strip() for x in base[header.index(m)].split("/")[:2]]
        sc = scenes[m]
        within = "%d%%" % round(100 * float(sc[4]))
        print("| `%s` | %s | %s (%s) | %s | %s |" % (m, mean_phi, median, ratio, sc[2], within))
    if "celc_acc" in scenes:  # not in the paper's nor the peers' study
        sc = scenes["celc_acc"]
        print("| `celc_acc` | - | - | %s | %d%% |" % (sc[2], round(100 * float(sc[4]))))


def cmd_readme(readme, path):
    with open(readme, encoding="utf-8") as f:
        text = f.read()
    with open(path, encoding="utf-8") as f:
        table = f.read().split("\n", 1)[1].strip("\n")  # without its Regenerate line
    if BEGIN not in text or END not in text:
        sys.exit("%s: no results markers" % readme)
    head, rest = text.split(BEGIN, 1)
    _, tail = rest.split(END, 1)
    with open(readme, "w", encoding="utf-8") as f:
        f.write(head + BEGIN + "\n" + table + "\n" + END + tail)


INCLUDE = re.compile(r"(<!-- include (results/[\w.-]+\.md) -->\n)(.*?)(<!-- end include -->)", re.S)


def cmd_include(pages):
    import os
    for page in pages:
        with open(page, encoding="utf-8") as f:
            text = f.read()

        def body(m):
            path = os.path.join(os.path.dirname(page), m.group(2))
            with open(path, encoding="utf-8") as f:
                lines = f.read().splitlines()
            spans = tables(lines)
            end = spans[-1][1] if spans else len(lines)
            return m.group(1) + "\n".join(lines[:end]).strip("\n") + "\n" + m.group(4)

        new = INCLUDE.sub(body, text)
        if new != text:
            with open(page, "w", encoding="utf-8") as f:
                f.write(new)
            print("updated %s" % page, file=sys.stderr)


def main():
    a = sys.argv[1:]
    if a[:1] == ["table"] and len(a) == 2:
        cmd_table(int(a[1]))
    elif a[:1] == ["block"] and len(a) == 2:
        cmd_block(a[1])
    elif a[:1] == ["put"] and len(a) == 3:
        cmd_put(a[1], a[2])
    elif a[:1] == ["windows"] and len(a) == 2:
        cmd_windows(a[1])
    elif a[:1] == ["summary"] and len(a) == 2:
        cmd_summary(a[1])
    elif a[:1] == ["include"] and len(a) >= 2:
        cmd_include(a[1:])
    elif a[:1] == ["readme"] and len(a) == 3:
        cmd_readme(a[1], a[2])
    else:
        sys.exit(__doc__)


if __name__ == "__main__":
    main()
