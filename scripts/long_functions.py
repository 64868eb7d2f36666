#!/usr/bin/env python3
"""Lists the C++ functions whose bodies span more than a number of lines.

usage: long_functions.py [--max N] [--all] [PATH ...]
PATHs are files or folders (default: lib/src/solver and apps, relative to the
repository root). A function's length counts the lines from its signature's
first line to its closing brace, lambdas and local classes inside it
included. Prints "LINES path:line name" per function longer than N lines
(default 80), longest first, and exits 1 when there is any; --all prints every
function and exits 0.

The parser is a brace matcher over the text with comments, strings and
character literals blanked: a block at namespace or class scope whose header
holds a parameter list (and no initialiser's `=` before it) is a function.
It needs no compiler, so any machine with Python 3 can run it.
"""
import os
import re
import signal
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DEFAULT_PATHS = ["lib/src/solver", "apps"]
EXTENSIONS = (".cpp", ".cc", ".hpp", ".h")

SCOPE_HEAD = re.compile(r"^(namespace|class|struct|union|enum|extern\s+\"C\")\b")
TEMPLATE_HEAD = re.compile(r"^template\s*<")
# What may follow a function's parameter list before its body.
FUNCTION_TAIL = re.compile(
    r"^(\s|const\b|noexcept\b(\s*\([^)]*\))?|override\b|final\b|mutable\b|volatile\b|&|"
    r"->\s*[\w:<>,\s\*&]+)*$")


def blank_literals(text):
    """The text with comments, string and character literals replaced by
    spaces (newlines kept), so braces inside them do not count."""
    out = []
    i, n = 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            out.append(" " * (j - i))
            i = j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif c == 'R' and text.startswith('R"', i) and (i == 0 or not text[i - 1].isalnum()):
            m = re.match(r'R"([^(\s]*)\(', text[i:])
            if not m:
                out.append(c)
                i += 1
                continue
            end = ")" + m.group(1) + '"'
            j = text.find(end, i + m.end())
            j = n if j < 0 else j + len(end)
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif c == '"' or (c == "'" and not (i > 0 and text[i - 1].isalnum())):
            j = i + 1
            while j < n and text[j] != c and text[j] != "\n":
                j += 2 if text[j] == "\\" else 1
            j = min(j + 1, n)
            out.append(" " * (j - i))
            i = j
        else:
            out.append(c)
            i += 1
    return "".join(out)


def skip_preprocessor(text):
    """The text with preprocessor lines (and their continuations) blanked."""
    lines = text.split("\n")
    cont = False
    for k, line in enumerate(lines):
        if cont or line.lstrip().startswith("#"):
            cont = line.rstrip().endswith("\\")
            lines[k] = ""
    return "\n".join(lines)


def matching_brace(text, i):
    """The index of the brace closing the one at i."""
    depth = 0
    for j in range(i, len(text)):
        if text[j] == "{":
            depth += 1
        elif text[j] == "}":
            depth -= 1
            if depth == 0:
                return j
    return len(text) - 1


def top_level(header):
    """The header with everything inside (), <> and {} removed, and the
    text after the last top-level ')'; None when there is no '('."""
    depth, last_close, flat = 0, -1, []
    for k, c in enumerate(header):
        if c in "({":
            if depth == 0:
                flat.append(c)
            depth += 1
        elif c in ")}":
            depth -= 1
            if depth == 0:
                last_close = k
        elif depth == 0:
            flat.append(c)
    return "".join(flat), (header[last_close + 1:] if last_close >= 0 else None)


def classify(header):
    """'scope', 'function', 'member_init' (a brace initialiser inside a
    constructor's initialiser list) or 'other' for the block whose header is
    the text before its opening brace."""
    h = header.strip()
    while TEMPLATE_HEAD.match(h):
        depth, k = 0, h.index("<")
        for k in range(h.index("<"), len(h)):
            depth += {"<": 1, ">": -1}.get(h[k], 0)
            if depth == 0:
                break
        h = h[k + 1:].strip()
    if SCOPE_HEAD.match(h) and "(" not in h.split("{")[0].split(":")[0]:
        return "scope"
    if "(" not in h:
        return "other"
    flat, tail = top_level(h)
    before_paren = flat.split("(")[0]
    if "=" in before_paren and "operator" not in before_paren:
        return "other"
    if tail is None:
        return "other"
    if FUNCTION_TAIL.match(tail):
        return "function"
    if tail.lstrip().startswith(":"):
        last = tail.rstrip()[-1:]
        return "member_init" if (last.isalnum() or last in "_>") else "function"
    return "other"


def function_name(header):
    flat, _ = top_level(header.strip())
    m = re.search(r"([~\w:]+(?:operator\s*\S+)?)\s*\($", flat.split("(")[0] + "(")
    return m.group(1) if m else "?"


def functions(text):
    """(first line, last line, name) of every function defined in text."""
    text = skip_preprocessor(blank_literals(text))
    found = []
    i, start, n = 0, 0, len(text)
    # Blocks at namespace or class scope: we only descend into those.
    while i < n:
        c = text[i]
        if c in ";}" or (c == ":" and re.search(r"\b(public|private|protected)\s*$", text[start:i])):
            start = i + 1
        elif c == "{":
            header = text[start:i]
            kind = classify(header)
            if kind == "scope":
                start = i + 1
            else:
                end = matching_brace(text, i)
                if kind == "function":
                    first = start + (len(header) - len(header.lstrip()))
                    found.append((text.count("\n", 0, first) + 1, text.count("\n", 0, end) + 1,
                                  function_name(header)))
                    start = end + 1
                i = end  # 'other' and 'member_init' keep the header growing
        i += 1
    return found


def source_files(paths):
    for p in paths:
        if os.path.isfile(p):
            yield p
            continue
        for d, _, names in sorted(os.walk(p)):
            for name in sorted(names):
                if name.endswith(EXTENSIONS):
                    yield os.path.join(d, name)


def main(argv):
    limit, show_all, paths = 80, False, []
    args = iter(argv)
    for a in args:
        if a == "--max":
            limit = int(next(args))
        elif a == "--all":
            show_all = True
        elif a in ("-h", "--help"):
            print(__doc__)
            return 0
        else:
            paths.append(a)
    if not paths:
        paths = [os.path.join(ROOT, p) for p in DEFAULT_PATHS]
    rows = []
    for path in source_files(paths):
        with open(path, encoding="utf-8", errors="replace") as f:
            for first, last, name in functions(f.read()):
                rows.append((last - first + 1, os.path.relpath(path, ROOT), first, name))
    rows.sort(key=lambda r: (-r[0], r[1], r[2]))
    long_rows = [r for r in rows if show_all or r[0] > limit]
    for length, path, line, name in long_rows:
        print("%4d %s:%d %s" % (length, path, line, name))
    return 0 if show_all or not long_rows else 1


if __name__ == "__main__":
    signal.signal(signal.SIGPIPE, signal.SIG_DFL)
    sys.exit(main(sys.argv[1:]))
