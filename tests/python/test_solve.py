"""celc.solve: the direction of simulated windows, agreement with `celc solve`,
degenerate windows, errors."""
import numpy as np
import pytest

import celc
from conftest import run_cli

SEEDS = range(1, 11)


def phi(v, truth):
    return float(np.arccos(np.clip(np.dot(v, truth), -1.0, 1.0)))


def test_recovers_the_direction_of_simulated_windows():
    """The paper's scene (5 lines x 200 events, v = (1, 2, 0) m/s, w = (0, 0, 2)
    rad/s, 0.5 s) with 1 px event noise. Over 40 seeds (1..40, measured with
    this module, docs/python.md) the error phi [rad] was: celc median 0.040,
    90th percentile 0.10, max 0.21; celc_ml median 0.013, 90th percentile
    0.037, max 0.10. The bounds below are about twice those figures, so they
    fail on a real regression, not on the draw of these ten seeds."""
    errors = {m: [] for m in ("celc", "celc_opt", "celc_ml")}
    for seed in SEEDS:
        w = celc.simulate_window(seed=seed, event_noise_px=1.0)
        r = celc.solve(w["events"], w["labels"], omega=w["omega"], calib=w["camera"], methods=list(errors))
        assert list(r) == list(errors)
        for m, res in r.items():
            assert res["status"] == "ok" and res["reason"] == "", (seed, m, res["message"])
            assert np.linalg.norm(res["v"]) == pytest.approx(1.0, abs=1e-9)
            e = phi(res["v"], w["direction"])
            errors[m].append(e)
            # sigma_deg is calibrated on such windows: a 2-DoF direction error
            # beyond 3 sigma has probability exp(-4.5) ~ 1%; none of the 30 are.
            assert e <= 3 * np.radians(res["sigma_deg"]), (seed, m, e, res["sigma_deg"])
    assert max(errors["celc"]) < 0.4 and np.median(errors["celc"]) < 0.08
    assert max(errors["celc_opt"]) < 0.4 and np.median(errors["celc_opt"]) < 0.08
    assert max(errors["celc_ml"]) < 0.2 and np.median(errors["celc_ml"]) < 0.03


def test_same_results_as_the_cli(tmp_path):
    """`celc solve` on the same labelled events (CSV t,x,y,cluster) and camera
    gives the same directions: one code path (clustersFromLabels, toObservations,
    solveMethods). The CLI prints 9 decimals."""
    w = celc.simulate_window(seed=3, event_noise_px=1.0)
    ev, labels = w["events"], w["labels"]
    csv = tmp_path / "labelled.csv"
    with open(csv, "w") as f:
        f.write("t,x,y,cluster\n")
        for e, c in zip(ev, labels):
            f.write(f"{float(e['t'])!r},{float(e['x'])!r},{float(e['y'])!r},{int(c)}\n")
    cam = w["camera"]
    calib = tmp_path / "calib.yaml"
    calib.write_text("camera:\n" + "".join(f"  {k}: {v}\n" for k, v in cam.items()))
    om = ",".join(repr(float(x)) for x in w["omega"])
    out = run_cli("solve", csv, "--omega", om, "--calib", calib, "-q").stdout.strip().splitlines()
    assert out[0] == "method,status,vx,vy,vz,runtime_us"
    py = celc.solve(ev, labels, omega=w["omega"], calib=calib)
    assert len(out) - 1 == len(py) == 6  # the six methods of celc solve and celc.solve
    for line in out[1:]:
        method, status, vx, vy, vz, _ = line.split(",")
        assert py[method]["status"] == status
        if status == "ok":
            np.testing.assert_allclose(py[method]["v"], [float(vx), float(vy), float(vz)], rtol=0, atol=1e-9)


def test_other_event_layouts_and_gyro():
    w = celc.simulate_window(seed=4, event_noise_px=1.0)
    ev = w["events"]
    plain = {"t": ev["t"].copy(), "x": ev["x"].astype(np.float64), "y": ev["y"].astype(np.float64)}
    a = celc.solve(ev, w["labels"], omega=w["omega"], calib=w["camera"], methods="celc")
    b = celc.solve(plain, w["labels"].astype(np.int64), omega=w["omega"], calib=w["camera"], methods="celc")
    np.testing.assert_array_equal(a["celc"]["v"], b["celc"]["v"])


def test_gyro_integrated_model():
    """The second motion model (velocity constant in the reference frame, R(t)
    integrated from gyro samples) on a window simulated with it; a constant
    rate (no wobble), given as 1 kHz samples covering the window."""
    w = celc.simulate_window(seed=4, event_noise_px=1.0, motion_model="gyro_integrated", omega_wobble=[0, 0, 0])
    t = np.linspace(0.0, 0.5, 501)
    gyro = np.column_stack([t, np.tile(w["omega"], (len(t), 1))])
    r = celc.solve(w["events"], w["labels"], gyro=gyro, calib=w["camera"], methods=["celc", "celc_ml"])
    for m, res in r.items():
        assert res["status"] == "ok", (m, res["message"])
    # The constant-twist model's bounds above (a single seed: the max bounds).
    assert phi(r["celc"]["v"], w["direction"]) < 0.4
    assert phi(r["celc_ml"]["v"], w["direction"]) < 0.2
    with pytest.raises(ValueError, match="gyro"):
        celc.solve(w["events"], w["labels"], gyro=gyro[:, :3], calib=w["camera"])


def test_no_motion_is_degenerate():
    w = celc.simulate_window(seed=1, velocity=[0, 0, 0])
    r = celc.solve(w["events"], w["labels"], omega=w["omega"], calib=w["camera"])
    for m, res in r.items():
        assert res["status"] == "degenerate" and res["reason"] == "no_parallax" and res["v"] is None, m
        assert np.isnan(res["sigma_deg"])


def test_errors(tmp_path):
    w = celc.simulate_window(seed=1, n_lines=3, events_per_line=50)
    ev, lab = w["events"], w["labels"]
    with pytest.raises(ValueError, match="labels"):
        celc.solve(ev, lab[:-1], calib=w["camera"])
    with pytest.raises(ValueError, match="calib"):
        celc.solve(ev, lab)
    with pytest.raises(ValueError, match="fast"):
        celc.solve(ev, lab, calib=w["camera"], methods=["fast"])
    with pytest.raises(ValueError, match="omega"):
        celc.solve(ev, lab, calib=w["camera"], omega=[1, 2])
    # No rotation is assumed silently.
    with pytest.raises(ValueError, match=r"give omega=\[wx, wy, wz\]"):
        celc.solve(ev, lab, calib=w["camera"])
    with pytest.raises(ValueError, match="solver.linear.no_such"):
        celc.solve(ev, lab, calib=w["camera"], set={"solver.linear.no_such": 1})
    missing = tmp_path / "missing_calib.yaml"
    with pytest.raises(FileNotFoundError, match="missing_calib.yaml"):
        celc.solve(ev, lab, calib=missing)


def test_camera_dict_is_read_each_time_it_changes():
    """solve() remembers the last camera dict (parsed once for a loop over
    windows); another dict must be read anew."""
    w = celc.simulate_window(seed=2, event_noise_px=1.0)
    args = (w["events"], w["labels"])
    a = celc.solve(*args, omega=w["omega"], calib=w["camera"], methods="celc")["celc"]["v"]
    other = dict(w["camera"], fx=200.0, fy=200.0)
    b = celc.solve(*args, omega=w["omega"], calib=other, methods="celc")["celc"]["v"]
    c = celc.solve(*args, omega=w["omega"], calib=w["camera"], methods="celc")["celc"]["v"]
    assert phi(a, b) > 1e-3  # another focal length: other bearings, another direction
    np.testing.assert_array_equal(a, c)
    with pytest.raises(ValueError, match="fx: must be > 0"):
        celc.solve(*args, calib=dict(w["camera"], fx=-1.0))
