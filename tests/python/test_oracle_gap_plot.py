"""scripts/plot_oracle_gap.py: the held-out windows' pipeline-against-oracle plot."""
import sys

from conftest import SOURCE_DIR, run_script, write_windows_run as write_run

SCRIPT = SOURCE_DIR / "scripts" / "plot_oracle_gap.py"


def run(*args):
    return run_script("plot_oracle_gap.py", *args)


def test_counts_the_windows_within_the_gap(tmp_path):
    # Oracle 0.01 rad (0.57 deg): within up to 1.57 deg (0.0274 rad). A refused
    # window counts as 180 deg; a window without an oracle and other methods are skipped.
    write_run(tmp_path / "a", ["0,celc_ml,ok,0.02,0.01\n", "1,celc_ml,ok,0.03,0.01\n",
                               "2,celc_ml,degenerate,,0.01\n", "3,celc_ml,ok,0.5,\n", "4,celc,ok,0.9,0.01\n"])
    out = tmp_path / "gap.png"
    proc = run(out, f"set a={tmp_path / 'a'}")
    assert proc.returncode == 0, proc.stderr
    assert out.stat().st_size > 10000
    # The legend's count, read back from the script's own function.
    sys.path.insert(0, str(SCRIPT.parent))
    import plot_oracle_gap
    points = plot_oracle_gap.read_points(str(tmp_path / "a"), "celc_ml")
    assert [round(o, 3) for o, _ in points] == [0.573] * 3
    assert sum(p <= plot_oracle_gap.gap_limit_deg(o) for o, p in points) == 1
    assert points[2][1] == 180.0


def test_a_run_without_truth_columns_is_an_error(tmp_path):
    write_run(tmp_path / "r", ["0,celc_ml,ok,0.1\n"], header="window,method,status,phi\n")
    proc = run(tmp_path / "x.png", f"r={tmp_path / 'r'}")
    assert proc.returncode != 0 and "no oracle_phi column" in proc.stderr
    proc = run(tmp_path / "x.png", f"none={tmp_path / 'missing'}")
    assert proc.returncode != 0 and "no <sequence>/windows.csv" in proc.stderr
    proc = run(tmp_path / "x.png", str(tmp_path))
    assert proc.returncode != 0 and "LABEL=RUNDIR" in proc.stderr
