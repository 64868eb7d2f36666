"""scripts/seed_spread.py: the oracle-gap counts of one set over runs with different seeds."""
from conftest import run_script, write_windows_run as write_run


def run(*args):
    return run_script("seed_spread.py", *args)


def test_counts_each_run_and_the_windows_that_move(tmp_path):
    # Oracle 0.01 rad (0.57 deg): within the gap up to 1.57 deg (0.0274 rad).
    # Window 0 stays at 0.02 rad in both runs; window 1 moves 0.02 -> 0.2 rad
    # (10.3 deg: spans more than 2 deg and leaves the gap); window 2 is
    # refused in the second run (180 deg); window 3 has no oracle in the
    # second run and is left out of both; other methods are skipped.
    write_run(tmp_path / "s1", ["0,celc_ml,ok,0.02,0.01\n", "1,celc_ml,ok,0.02,0.01\n",
                                "2,celc_ml,ok,0.5,0.01\n", "3,celc_ml,ok,0.02,0.01\n", "0,celc,ok,0.9,0.01\n"])
    write_run(tmp_path / "s2", ["0,celc_ml,ok,0.02,0.01\n", "1,celc_ml,ok,0.2,0.01\n",
                                "2,celc_ml,degenerate,,0.01\n", "3,celc_ml,ok,0.02,\n"])
    proc = run(f"set a={tmp_path / 's1'},{tmp_path / 's2'}")
    assert proc.returncode == 0, proc.stderr
    row = [line for line in proc.stdout.splitlines() if line.startswith("| set a ")][0]
    cells = [c.strip() for c in row.strip("|").split("|")]
    # windows, within per run, median phi per run [deg], spread > 2 deg, flipped
    assert cells[1:] == ["3", "2 / 1", "1.15 / 11.46", "2", "1"]


def test_bad_arguments_are_errors(tmp_path):
    write_run(tmp_path / "a", ["0,celc_ml,ok,0.02,0.01\n"])
    proc = run(f"one={tmp_path / 'a'}")
    assert proc.returncode != 0 and "at least two runs" in proc.stderr
    proc = run(str(tmp_path / "a"))
    assert proc.returncode != 0 and "LABEL=RUNDIR" in proc.stderr
    write_run(tmp_path / "b", ["0,celc_ml,ok,0.1\n"], header="window,method,status,phi\n")
    proc = run(f"x={tmp_path / 'a'},{tmp_path / 'b'}")
    assert proc.returncode != 0 and "no oracle_phi column" in proc.stderr
