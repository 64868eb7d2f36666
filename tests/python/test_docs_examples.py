"""Every ```python block of docs/python.md runs as written from the repository
root, and prints what the ```text block right after it shows (when there is one).

Each block runs in its own interpreter (this one: /usr/bin/python3 under CTest)
with the source root as working directory, so that the examples' relative
paths (data/sample_seq/...) are the reader's. The module is found as the other
tests find it: PYTHONPATH (CTest sets it to the build's python/ folder), else
build/python under the source root (conftest.SOURCE_DIR).
"""
import os
import pathlib
import re
import subprocess
import sys

import pytest

from conftest import SOURCE_DIR

DOC = SOURCE_DIR / "docs" / "python.md"
# A python block, then optionally (only blank lines between) a text block with its output.
BLOCK = re.compile(r"^```python\n(.*?)^```\n(?:\s*^```text\n(.*?)^```\n)?", re.MULTILINE | re.DOTALL)


def examples():
    text = DOC.read_text(encoding="utf-8")
    found = [(m.group(1), m.group(2)) for m in BLOCK.finditer(text)]
    # Every python block is matched (none hidden by a formatting slip).
    assert len(found) == text.count("```python\n"), "a ```python block that the pattern did not match"
    return found


def module_env():
    env = dict(os.environ)
    paths = [p for p in env.get("PYTHONPATH", "").split(os.pathsep) if p]
    if not any(pathlib.Path(p, "celc").exists() or list(pathlib.Path(p).glob("celc*.so")) for p in paths):
        paths.insert(0, str(SOURCE_DIR / "build" / "python"))
    env["PYTHONPATH"] = os.pathsep.join(paths)
    env.setdefault("MPLBACKEND", "Agg")
    return env


EXAMPLES = examples()


def test_the_page_has_examples():
    assert len(EXAMPLES) >= 5


@pytest.mark.parametrize("code,expected", EXAMPLES, ids=[f"block{i + 1}" for i in range(len(EXAMPLES))])
def test_example_runs_and_prints_what_the_page_shows(code, expected):
    env = module_env()
    probe = subprocess.run([sys.executable, "-c", "import celc"], cwd=SOURCE_DIR, env=env,
                           capture_output=True, text=True)
    if probe.returncode != 0:
        pytest.skip(f"the celc module is not importable (build it first): {probe.stderr.strip()[-200:]}")
    proc = subprocess.run([sys.executable, "-c", code], cwd=SOURCE_DIR, env=env, capture_output=True, text=True,
                          timeout=600)
    assert proc.returncode == 0, f"the example failed:\n{code}\n--- stderr ---\n{proc.stderr}"
    if expected is not None:
        got = [line.rstrip() for line in proc.stdout.strip("\n").splitlines()]
        want = [line.rstrip() for line in expected.strip("\n").splitlines()]
        assert got == want, f"the example printed:\n{proc.stdout}\nthe page shows:\n{expected}"
