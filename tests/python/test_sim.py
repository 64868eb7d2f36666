"""celc.simulate_window and celc.synth."""
import numpy as np
import pytest

import celc
from conftest import SCENE_YAML


def test_simulate_window_is_deterministic():
    a = celc.simulate_window(seed=5, n_lines=4, events_per_line=100)
    b = celc.simulate_window(seed=5, n_lines=4, events_per_line=100)
    c = celc.simulate_window(seed=6, n_lines=4, events_per_line=100)
    assert a["events"].dtype == celc.EVENT_DTYPE
    assert len(a["events"]) == len(a["labels"]) == 400
    np.testing.assert_array_equal(a["events"], b["events"])
    assert not np.array_equal(a["events"]["x"], c["events"]["x"])
    assert set(np.unique(a["labels"])) == {0, 1, 2, 3}
    assert a["segments"].shape == (4, 2, 3)
    # The truth: the unit direction of the configured velocity (1, 2, 0).
    np.testing.assert_allclose(a["direction"], np.array([1, 2, 0]) / np.sqrt(5), atol=1e-12)
    np.testing.assert_allclose(a["omega"], [0, 0, 2], atol=1e-12)  # omega_noise = 0


def test_simulate_window_options():
    w = celc.simulate_window(seed=1, velocity=[0, 0, 3], camera={"fx": 200, "fy": 200}, duration=0.2)
    np.testing.assert_allclose(w["direction"], [0, 0, 1], atol=1e-12)
    assert w["camera"]["fx"] == 200
    assert w["events"]["t"].max() <= 0.2
    with pytest.raises(ValueError, match="n_line"):
        celc.simulate_window(n_line=3)
    with pytest.raises(ValueError, match="n_lines"):
        celc.simulate_window(n_lines="many")


def test_synth_from_text_and_path(tmp_path):
    text = SCENE_YAML.read_text()
    s = celc.synth(text, tmp_path / "a", duration=0.05, seed=2)
    ev = celc.read_events(tmp_path / "a")
    assert s["events"] == len(ev) > 1000
    assert s["imu_samples"] == len(celc.read_imu(tmp_path / "a"))
    # The same scene from its file: the same events (seeded).
    s2 = celc.synth(SCENE_YAML, tmp_path / "b", duration=0.05, seed=2)
    assert s2["events"] == s["events"]
    np.testing.assert_array_equal(celc.read_events(tmp_path / "b"), ev)
    with pytest.raises(ValueError, match="not empty"):
        celc.synth(SCENE_YAML, tmp_path / "a", duration=0.05)
    celc.synth(SCENE_YAML, tmp_path / "a", duration=0.02, force=True)


def test_synth_errors(tmp_path):
    with pytest.raises(ValueError, match="no_such_key"):
        celc.synth(SCENE_YAML.read_text() + "\nno_such_key: 2\n", tmp_path / "c")
    with pytest.raises(FileNotFoundError, match="missing_scene.yaml"):
        celc.synth(tmp_path / "missing_scene.yaml", tmp_path / "d")
