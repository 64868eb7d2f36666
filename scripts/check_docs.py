#!/usr/bin/env python3
"""Checks the documentation rules (run by CTest as `docs_check`).

usage: check_docs.py [ROOT]

- README.md is under 12 KB; every page under docs/ under 25 KB.
- No narration of the development history (numbered rounds of work,
  "since the" with an ordinal, issue numbers as history) in README, docs,
  lib, apps, tests, scripts, python, config; docs/decisions.md,
  the other docs/decisions_*.md pages and CHANGELOG.md are the places for
  history and are not checked.
- Every Markdown table of figures (a quarter or more of its body cells are
  numbers with a decimal point or a percentage) in README.md and docs/ names the command that regenerates it on a
  "Regenerate:" line at most 8 lines above it (a file of docs/results/ may
  name it once, on its first line).
- Every relative link in README.md and docs/ points at a file that exists.
Prints one line per finding (FILE:LINE: what) and exits 1 when any.
"""
import os
import re
import sys

WORK = "sess" + "ion"  # spelled in two pieces so that this file does not match itself
HISTORY = re.compile(
    r"\b" + WORK + r"s?\b"
    r"|\b(first|second|third|fourth|fifth|sixth|seventh|eighth|ninth|tenth|eleventh|twelfth"
    r"|thirteenth|fourteenth|fifteenth|sixteenth|seventeenth|eighteenth|nineteenth|twentieth"
    r"|twenty-\w+|thirtieth)\s+(" + WORK + r"|change|round|iteration)\b"
    r"|\bsince the (\w+th|\w+st|\w+nd|\w+rd)\b"
    r"|\b(before|until|after) the (\w+th|\w+st|\w+nd|\w+rd) (" + WORK + r"|change)\b"
    r"|\b[Ii]ssue[ -]\d+\b"
    r"|\b(since|until|before|after|as of|measured)\s+20\d\d-[01]\d-[0-3]\d\b",
    re.IGNORECASE)
# pytest's fixture scope of that name is an API name, not history.
HISTORY_ALLOWED = re.compile(r'scope="' + WORK + '"')
CODE_DIRS = ["lib", "apps", "tests", "scripts", "python", "config", "cmake", ".ci"]
SKIP_FILES = {"docs/decisions.md", "docs/decisions_2026-12-07.md", "docs/decisions_2026-12-06.md",
              "docs/decisions_earlier.md", "docs/decisions_io.md", "CHANGELOG.md"}
NUMBER = re.compile(r"^[~<>=+-]*\s*[0-9][0-9.,eE+\-]*\s*(%|x|ms|us|s|deg|rad|px|MB|KB|M/s)?"
                    r"(\s*[(/].*)?$")
LINK = re.compile(r"\[[^\]]*\]\(([^)\s]+)\)")


def rel(root, path):
    return os.path.relpath(path, root)


def markdown_files(root):
    out = [os.path.join(root, "README.md")]
    for d, _, files in os.walk(os.path.join(root, "docs")):
        out += [os.path.join(d, f) for f in files if f.endswith(".md")]
    return sorted(out)


def check_sizes(root, findings):
    readme = os.path.join(root, "README.md")
    if os.path.getsize(readme) >= 12 * 1024:
        findings.append("README.md: %d bytes (limit 12 KB)" % os.path.getsize(readme))
    for f in markdown_files(root):
        if f != readme and os.path.getsize(f) > 25 * 1024:
            findings.append("%s: %d bytes (limit 25 KB)" % (rel(root, f), os.path.getsize(f)))


def check_history(root, findings):
    files = [os.path.join(root, "README.md")] + markdown_files(root)
    for d in CODE_DIRS:
        for base, dirs, names in os.walk(os.path.join(root, d)):
            dirs[:] = [x for x in dirs if x not in ("__pycache__",)]
            files += [os.path.join(base, n) for n in names]
    for f in sorted(set(files)):
        r = rel(root, f)
        if r in SKIP_FILES or r.startswith("docs/results/") and r.endswith(".png"):
            continue
        try:
            with open(f, encoding="utf-8") as fh:
                lines = fh.readlines()
        except (UnicodeDecodeError, OSError):
            continue  # binary fixtures
        for i, line in enumerate(lines, 1):
            if HISTORY.search(line) and not HISTORY_ALLOWED.search(line):
                findings.append("%s:%d: history: %s" % (r, i, line.strip()[:100]))


def table_blocks(lines):
    """(first line index, body rows) of every Markdown table."""
    i = 0
    while i < len(lines):
        if lines[i].lstrip().startswith("|") and i + 1 < len(lines) and re.match(r"^\s*\|[\s:|-]+\|\s*$", lines[i + 1]):
            start = i
            i += 2
            body = []
            while i < len(lines) and lines[i].lstrip().startswith("|"):
                body.append(lines[i])
                i += 1
            yield start, body
        else:
            i += 1


def is_figures(body):
    cells = []
    for row in body:
        parts = [c.strip().strip("*`") for c in row.strip().strip("|").split("|")]
        cells += parts[1:]  # the first column names the row
    if not cells:
        return False
    # Measured figures carry a decimal point or a percentage; counts, sizes
    # and defaults (integers) alone do not make a table of figures.
    numeric = sum(1 for c in cells if c and NUMBER.match(c) and re.search(r"\d\.\d|%", c))
    return numeric >= 0.25 * len(cells)


def check_tables(root, findings):
    for f in markdown_files(root):
        r = rel(root, f)
        if r.startswith("docs/configuration/"):
            continue  # generated key reference: defaults, not measurements
        with open(f, encoding="utf-8") as fh:
            lines = fh.readlines()
        for start, body in table_blocks(lines):
            if not is_figures(body):
                continue
            above = lines[max(0, start - 8):start]
            file_wide = r.startswith("docs/results/") and lines and lines[0].startswith("Regenerate:")
            if not file_wide and not any("Regenerate:" in a for a in above):
                findings.append("%s:%d: table of figures without a 'Regenerate:' line above it" % (r, start + 1))


def check_links(root, findings):
    for f in markdown_files(root):
        r = rel(root, f)
        with open(f, encoding="utf-8") as fh:
            for i, line in enumerate(fh, 1):
                for target in LINK.findall(line):
                    if re.match(r"^[a-z]+:", target) or target.startswith("#"):
                        continue
                    path = target.split("#")[0]
                    if path and not os.path.exists(os.path.join(os.path.dirname(f), path)):
                        findings.append("%s:%d: broken link %s" % (r, i, target))


def main():
    root = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), ".."))
    findings = []
    check_sizes(root, findings)
    check_history(root, findings)
    check_tables(root, findings)
    check_links(root, findings)
    for line in findings:
        print(line)
    print("check_docs: %d finding(s)" % len(findings), file=sys.stderr)
    return 1 if findings else 0


if __name__ == "__main__":
    sys.exit(main())
