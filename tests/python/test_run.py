"""celc.run against `celc run` on the same input: the same rows."""
import csv

import numpy as np
import pytest

import celc
from conftest import run_cli

METHODS = "celc,celc_opt,ce3lc,npt"  # celc_ml's lattice of starts is the slow part; not needed to compare paths


def read_windows_csv(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def test_run_matches_cli(synth_seq, tmp_path):
    out = tmp_path / "cli_run"
    run_cli("run", synth_seq, "-o", out, "--window-seconds", "0.1", "--methods", METHODS, "--no-plots", "-q",
            "--threads", "2")
    cli = read_windows_csv(out / "windows.csv")
    py = celc.run(synth_seq, window_seconds=0.1, methods=METHODS.split(","), threads=2)

    header = open(out / "windows.csv").readline().strip().split(",")
    assert list(py.keys()) == header
    n = len(py["window"])
    assert n == len(cli) > 0
    assert all(len(col) == n for col in py.values())
    assert set(py["method"]) == set(METHODS.split(","))
    for i, row in enumerate(cli):
        for key in header:
            if key == "runtime_ms":  # wall time: differs from run to run
                continue
            value = py[key][i]
            if key in ("method", "status", "reason", "sigma_rule", "model"):
                assert value == row[key], (i, key)
            elif key in ("window", "n_events", "n_clusters", "n_lines"):
                assert value == (int(row[key]) if row[key] else -1), (i, key)
            elif row[key] == "":
                assert np.isnan(value), (i, key)
            else:
                # The same digits: both are windows.csv's text of the same numbers.
                assert value == float(row[key]), (i, key, value, row[key])
    # The scene moves (4 m/s): most windows give an estimate with ground truth.
    ok = py["status"] == "ok"
    assert ok.sum() >= n // 2
    assert np.all(np.isfinite(py["phi"][ok]))


def test_run_config_dict_and_set(synth_seq):
    a = celc.run(synth_seq, config={"windows": {"policy": "seconds", "seconds": 0.1}}, methods="celc", threads=1)
    b = celc.run(synth_seq, set={"windows.seconds": 0.1, "windows.policy": "seconds", "methods": ["celc"]})
    np.testing.assert_array_equal(a["vx"], b["vx"])
    np.testing.assert_array_equal(a["status"], b["status"])


def test_run_errors(tmp_path, synth_seq):
    with pytest.raises(FileNotFoundError, match="missing_seq"):
        celc.run(tmp_path / "missing_seq")
    with pytest.raises(FileNotFoundError, match="missing_calib.yaml"):
        celc.run(synth_seq, calib=tmp_path / "missing_calib.yaml")
    # A file that is not a recording: the reader's one-line error, naming it.
    junk = tmp_path / "junk.aedat4"
    junk.write_bytes(b"#!AER-DAT4.0\r\n" + bytes(200))
    with pytest.raises(OSError, match="junk.aedat4"):
        celc.run(junk, calib=synth_seq / "calib.yaml", omega=[0, 0, 0])
    with pytest.raises(ValueError, match="cluster.no_such_key"):
        celc.run(synth_seq, set={"cluster.no_such_key": 1})
    with pytest.raises(ValueError, match="nope"):
        celc.run(synth_seq, methods=["nope"])
    with pytest.raises(ValueError, match="threads"):
        celc.run(synth_seq, threads=-1)
