"""Shared fixtures of the Python module's tests (run by CTest: python_module).

The module is imported from the build tree (PYTHONPATH=build/python); the CLI
`celc` (CELC_BINARY) writes the reference files and runs the reference runs.
"""
import os
import pathlib
import subprocess
import sys

import pytest

SOURCE_DIR = pathlib.Path(os.environ.get("CELC_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))
CELC_BINARY = os.environ.get("CELC_BINARY", str(SOURCE_DIR / "build" / "celc"))

# The end-to-end room (three textured planes 1-2.5 m away, DAVIS346 at 4 m/s),
# rendered for 0.3 s: three 0.1 s windows of ~140,000 events, a few seconds.
SCENE_YAML = (SOURCE_DIR / "config" / "scenes" / "e2e_davis346_room_fast.yaml")


def run_cli(*args, cwd=None):
    """Runs the CLI; fails the test with its stderr when it fails."""
    proc = subprocess.run([CELC_BINARY, *map(str, args)], cwd=cwd, capture_output=True, text=True)
    assert proc.returncode == 0, f"celc {' '.join(map(str, args))} failed:\n{proc.stderr}"
    return proc


def run_script(script, *args):
    """Runs a script of scripts/ with this interpreter; returns the finished process."""
    return subprocess.run([sys.executable, str(SOURCE_DIR / "scripts" / script), *map(str, args)],
                          capture_output=True, text=True)


def write_windows_run(root, rows, header="window,method,status,phi,oracle_phi\n"):
    """A run folder of one sequence, root/seq/windows.csv, with the given CSV rows."""
    (root / "seq").mkdir(parents=True)
    (root / "seq" / "windows.csv").write_text(header + "".join(rows))


@pytest.fixture(scope="session")
def synth_seq(tmp_path_factory):
    """A sequence directory written by `celc synth` (the tool, not this module)."""
    out = tmp_path_factory.mktemp("synth") / "seq"
    run_cli("synth", SCENE_YAML, "-o", out, "--duration", "0.3", "--seed", "3", "-q")
    return out
