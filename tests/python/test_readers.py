"""celc.read_events / read_imu / write_events / info: round trips through the
library's writers and the files `celc synth` writes, dtypes, ownership, errors."""
import os

import numpy as np
import pytest

import celc


def make_events(n=5000, seed=7, width=346, height=260):
    """n events on integer pixels (every format stores integers) at increasing
    whole-microsecond times (the binary formats store microseconds)."""
    rng = np.random.default_rng(seed)
    ev = np.zeros(n, dtype=celc.EVENT_DTYPE)
    ev["t"] = 0.5 + np.cumsum(rng.integers(1, 50, n)) * 1e-6
    ev["x"] = rng.integers(0, width, n)
    ev["y"] = rng.integers(0, height, n)
    ev["p"] = rng.random(n) < 0.5
    return ev


def make_imu(n=200, seed=8):
    rng = np.random.default_rng(seed)
    imu = np.zeros(n, dtype=celc.IMU_DTYPE)
    imu["t"] = 0.5 + np.arange(n) * 1e-3
    imu["gyro"] = rng.uniform(-3, 3, (n, 3))      # rad/s, inside +-1000 deg/s
    imu["acc"] = rng.uniform(-20, 20, (n, 3))     # m/s^2, inside +-8 g
    return imu


def test_dtypes_match_the_library_records():
    assert celc.EVENT_DTYPE.names == ("t", "x", "y", "p")
    assert celc.EVENT_DTYPE.itemsize == 24  # sizeof(celc::Event): read in place, no repacking
    assert celc.EVENT_DTYPE["t"] == np.float64 and celc.EVENT_DTYPE["x"] == np.float32
    assert celc.EVENT_DTYPE["p"] == np.bool_
    assert celc.IMU_DTYPE.names == ("t", "gyro", "acc")
    assert celc.IMU_DTYPE["gyro"].shape == (3,)


@pytest.mark.parametrize("fmt", ["text", "aedat2", "aedat31", "aedat4"])
def test_event_round_trip(tmp_path, fmt):
    ev = make_events()
    path = tmp_path / f"events.{fmt}"
    celc.write_events(path, ev, format=fmt, chip="DAVIS346", width=346, height=260)
    back = celc.read_events(path)
    assert back.dtype == celc.EVENT_DTYPE
    assert len(back) == len(ev)
    # Text keeps 9 decimals of t, the binary formats whole microseconds: the
    # times were drawn on whole microseconds, so both give them back to
    # float64 rounding (1e-12 s at t ~ 1 s).
    np.testing.assert_allclose(back["t"], ev["t"], rtol=0, atol=1e-9)
    np.testing.assert_array_equal(back["x"], ev["x"])
    np.testing.assert_array_equal(back["y"], ev["y"])
    np.testing.assert_array_equal(back["p"], ev["p"])
    assert back[0]["t"] == pytest.approx(ev[0]["t"], abs=1e-9)
    assert back[-1]["t"] == pytest.approx(ev[-1]["t"], abs=1e-9)


@pytest.mark.parametrize("fmt,gyro_tol,acc_tol", [
    # AEDAT 2.0 quantises to int16 over the full scale: 1000 deg/s and 8 g
    # over 32768 counts are 5.3e-4 rad/s and 2.4e-3 m/s^2; half a count plus rounding.
    ("aedat2", 6e-4, 3e-3),
    # AEDAT 3.1 and 4.0 store float32: relative 6e-8 of values below 20.
    ("aedat31", 1e-5, 1e-5),
    ("aedat4", 1e-5, 1e-5),
])
def test_imu_round_trip(tmp_path, fmt, gyro_tol, acc_tol):
    ev, imu = make_events(), make_imu()
    path = tmp_path / f"rec.{fmt}"
    celc.write_events(path, ev, format=fmt, imu=imu, chip="DAVIS346")
    back = celc.read_imu(path)
    assert back.dtype == celc.IMU_DTYPE
    assert len(back) == len(imu)
    np.testing.assert_allclose(back["t"], imu["t"], rtol=0, atol=1e-9)
    np.testing.assert_allclose(back["gyro"], imu["gyro"], rtol=0, atol=gyro_tol)
    np.testing.assert_allclose(back["acc"], imu["acc"], rtol=0, atol=acc_tol)


def test_reader_buffer_is_handed_over_without_copy(tmp_path):
    path = tmp_path / "events.txt"
    celc.write_events(path, make_events(1000))
    back = celc.read_events(path)
    assert not back.flags.owndata and back.base is not None  # numpy holds the reader's buffer (a capsule)
    assert back.flags.c_contiguous and back.flags.writeable
    view = back[10:20]
    del back  # the view keeps the buffer alive through the capsule
    assert len(view) == 10 and view["t"].min() > 0


def test_synth_directory_matches_its_text(synth_seq):
    """The directory `celc synth` wrote, read by the library, against numpy's
    own parse of its events.txt and imu.txt."""
    back = celc.read_events(synth_seq)
    ref = np.loadtxt(synth_seq / "events.txt")
    assert len(back) == len(ref) > 10000
    np.testing.assert_allclose(back["t"], ref[:, 0], rtol=0, atol=1e-12)
    np.testing.assert_array_equal(back["x"], ref[:, 1])
    np.testing.assert_array_equal(back["y"], ref[:, 2])
    np.testing.assert_array_equal(back["p"], ref[:, 3] > 0)
    imu = celc.read_imu(synth_seq)
    ref_imu = np.loadtxt(synth_seq / "imu.txt")  # t ax ay az gx gy gz
    assert len(imu) == len(ref_imu)
    np.testing.assert_allclose(imu["acc"], ref_imu[:, 1:4], rtol=0, atol=1e-12)
    np.testing.assert_allclose(imu["gyro"], ref_imu[:, 4:7], rtol=0, atol=1e-12)
    info = celc.info(synth_seq)
    assert info["events"] == len(back) and info["imu_samples"] == len(imu)


def test_time_range_and_count(tmp_path):
    ev = make_events(20000)
    path = tmp_path / "rec.aedat4"
    celc.write_events(path, ev, format="aedat4")
    t0, t1 = ev["t"][5000], ev["t"][12000]
    part = celc.read_events(path, t0=t0, t1=t1)
    assert len(part) == 7000
    np.testing.assert_allclose(part["t"], ev["t"][5000:12000], atol=1e-9)
    assert len(celc.read_events(path, max_events=123)) == 123
    # A reversed, empty or NaN range is an error, not an empty array.
    for lo, hi in ((t1, t0), (t0, t0), (float("nan"), t1)):
        with pytest.raises(ValueError, match="need t0 < t1"):
            celc.read_events(path, t0=lo, t1=hi)


def test_reader_options(tmp_path):
    ev = make_events(100)
    path = tmp_path / "events_us.txt"
    with open(path, "w") as f:
        for e in ev:
            f.write(f"{round(e['t'] * 1e6)} {int(e['x'])} {int(e['y'])} {int(e['p'])}\n")
    back = celc.read_events(path, options={"time_scale": 1e-6})
    np.testing.assert_allclose(back["t"], ev["t"], atol=1e-9)


def test_missing_file_is_oserror_naming_it(tmp_path):
    path = tmp_path / "no_such_file.aedat4"
    with pytest.raises(OSError, match="no_such_file.aedat4"):
        celc.read_events(path)


def test_bytes_and_nul_paths(tmp_path):
    ev = make_events(50)
    path = tmp_path / "rec.aedat4"
    celc.write_events(path, ev, format="aedat4")
    # A bytes path is decoded as the file system does, not read as "b'...'".
    assert len(celc.read_events(os.fsencode(str(path)))) == 50
    with pytest.raises(ValueError, match="NUL byte"):
        celc.read_events(str(path) + "\0tail")
    # A control character in a missing file's name is shown escaped.
    with pytest.raises(OSError) as e:
        celc.read_events(tmp_path / "no\x1b[31mfile")
    assert "\x1b" not in str(e.value)


def test_corrupt_file_is_oserror_naming_it(tmp_path):
    path = tmp_path / "broken.aedat"
    path.write_bytes(b"#!AER-DAT4.0\r\n" + bytes(range(256)) * 4)
    with pytest.raises(OSError, match="broken.aedat"):
        celc.read_events(path)


def test_bad_option_is_valueerror(tmp_path):
    path = tmp_path / "events.txt"
    celc.write_events(path, make_events(10))
    with pytest.raises(ValueError, match="no_such_key"):
        celc.read_events(path, options={"no_such_key": 1})
    with pytest.raises(ValueError, match="compression"):
        celc.write_events(tmp_path / "x.aedat4", make_events(10), format="aedat4", compression="zip")
