"""scripts/heldout_scenes.py: the held-out scene files that scripts/cluster_table.sh renders."""
import math
import re
import subprocess
import sys

import celc
from conftest import SOURCE_DIR

SCRIPT = SOURCE_DIR / "scripts" / "heldout_scenes.py"
KINDS = ["room", "hand", "rect", "deep", "lines"]


def write_scenes(out, *args):
    """Runs the script; returns its printed lines (one per scene)."""
    proc = subprocess.run([sys.executable, str(SCRIPT), str(out), *map(str, args)], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    return proc.stdout.splitlines()


def motion(text, key):
    """The trajectory's v or w of a scene file."""
    return [float(x) for x in re.search(rf"^\s*{key}: \[([^\]]*)\]", text, re.M).group(1).split(",")]


def test_every_kind_renders_and_draws_its_motion_in_range(tmp_path):
    lines = write_scenes(tmp_path / "s", "--count", len(KINDS), "--seed", 3, "--kinds", ",".join(KINDS),
                         "--speed", "1,4", "--rate", "0.3,3")
    assert len(lines) == len(KINDS)
    for i, kind in enumerate(KINDS):
        scene = tmp_path / "s" / f"h{i:02d}_{kind}.yaml"
        text = scene.read_text()
        # Speeds and rates are drawn in the ranges asked for (0.01 of rounding).
        assert 1.0 - 0.01 <= math.hypot(*motion(text, "v")) <= 4.0 + 0.01, kind
        assert 0.3 - 0.01 <= math.hypot(*motion(text, "w")) <= 3.0 + 0.01, kind
        summary = celc.synth(scene, tmp_path / kind, duration=0.02)
        assert summary["events"] > 0, kind


def test_lines_scenes_hold_bars_only(tmp_path):
    write_scenes(tmp_path / "s", "--count", 2, "--seed", 5, "--kinds", "lines")
    for i in range(2):
        scene = tmp_path / "s" / f"h{i:02d}_lines.yaml"
        text = scene.read_text()
        assert text.count("texture: segments") == 3 and "texture:" not in text.replace("texture: segments", "")
        assert "rectangles" not in text and "chessboard" not in text
        # A far wall at 5-6 m and two planes at 3-4 m.
        depths = sorted(float(m) for m in re.findall(r"^\s+position: \[[^,]*, [^,]*, ([0-9.]+)\]", text, re.M))
        assert 3.0 <= depths[0] <= depths[1] <= 4.0 <= 5.0 <= depths[2] <= 6.0
        celc.synth(scene, tmp_path / f"r{i}", duration=0.02)
        # 4 border edges per plane and 4 per bar: 4 + 4 x 4 + 2 x (4 + 2 x 4).
        assert len((tmp_path / f"r{i}" / "edges.txt").read_text().splitlines()) == 44


def test_same_seed_same_scenes(tmp_path):
    write_scenes(tmp_path / "a", "--count", 3, "--seed", 9, "--kinds", "lines,room")
    write_scenes(tmp_path / "b", "--count", 3, "--seed", 9, "--kinds", "lines,room")
    for name in ["h00_lines", "h01_room", "h02_lines"]:
        assert (tmp_path / "a" / f"{name}.yaml").read_text() == (tmp_path / "b" / f"{name}.yaml").read_text()


def test_unknown_kind_is_refused(tmp_path):
    proc = subprocess.run([sys.executable, str(SCRIPT), str(tmp_path), "--kinds", "room,bars"],
                          capture_output=True, text=True)
    assert proc.returncode != 0 and "unknown kind 'bars'" in proc.stderr
