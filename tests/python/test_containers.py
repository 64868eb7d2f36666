"""ROS bags and HDF5 files through celc.read_events / read_imu / run: the
io fixtures (tests/fixtures/make_fixtures.sh, made by the io_fixtures CTest
setup into build/io_fixtures) hold the same rendered sequence as seq/ in
text form."""
import os
import pathlib

import numpy as np
import pytest

import celc

FIXTURES = pathlib.Path(os.environ.get("CELC_FIXTURE_DIR", "build/io_fixtures"))
pytestmark = pytest.mark.skipif(not (FIXTURES / "complete").exists(),
                                reason=f"no io fixtures in {FIXTURES} (ctest makes them: io_fixtures)")


@pytest.mark.parametrize("name", ["seq_lz4.bag", "seq_none.bag", "seq_dsec.h5", "seq_mvsec.h5"])
def test_container_events_match_the_text(name):
    ref = celc.read_events(FIXTURES / "seq")
    ev = celc.read_events(FIXTURES / name)
    assert ev.dtype == celc.EVENT_DTYPE
    assert len(ev) == len(ref) > 1000
    np.testing.assert_array_equal(ev["x"], ref["x"])
    np.testing.assert_array_equal(ev["y"], ref["y"])
    np.testing.assert_array_equal(ev["p"], ref["p"])
    # Whole microseconds in every container (MVSEC: float64 seconds of them).
    np.testing.assert_allclose(ev["t"], ref["t"], rtol=0, atol=1e-9)


@pytest.mark.parametrize("name", ["seq_lz4.bag", "seq_mvsec.h5"])
def test_container_imu_matches_the_text(name):
    ref = celc.read_imu(FIXTURES / "seq")
    imu = celc.read_imu(FIXTURES / name)
    assert len(imu) == len(ref) > 10
    np.testing.assert_allclose(imu["t"], ref["t"], rtol=0, atol=1e-9)
    np.testing.assert_allclose(imu["gyro"], ref["gyro"], rtol=0, atol=1e-12)
    np.testing.assert_allclose(imu["acc"], ref["acc"], rtol=0, atol=1e-12)


def test_run_on_a_bag_takes_its_camera_and_poses():
    rows = celc.run(FIXTURES / "seq_lz4.bag", window_events=50000, methods="celc", threads=1)
    assert len(rows["window"]) >= 2
    assert np.isfinite(rows["gt_vx"]).all()  # poses from the bag: ground truth in every window


def test_bad_container_names_the_file():
    with pytest.raises(OSError, match="bad_layout.h5"):
        celc.read_events(FIXTURES / "bad_layout.h5")
    with pytest.raises(OSError, match="bad_truncated.bag"):
        celc.read_events(FIXTURES / "bad_truncated.bag", options={"strict": True})
