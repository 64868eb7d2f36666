"""Long calls release the GIL: a Python thread keeps running meanwhile."""
import threading
import time

import celc
from conftest import SCENE_YAML


def test_long_calls_release_the_gil(tmp_path):
    ticks = []
    stop = threading.Event()

    def spin():
        while not stop.is_set():
            ticks.append(time.perf_counter())
            time.sleep(0.001)

    thread = threading.Thread(target=spin)
    thread.start()
    try:
        time.sleep(0.01)
        start = time.perf_counter()
        celc.synth(SCENE_YAML, tmp_path / "s", duration=0.1)
        middle = time.perf_counter()
        ev = celc.read_events(tmp_path / "s")
        rows = celc.run(tmp_path / "s", window_seconds=0.05, methods="celc", threads=1)
        end = time.perf_counter()
    finally:
        stop.set()
        thread.join()
    assert len(ev) > 0 and len(rows["window"]) > 0
    # With the GIL held through a call the thread could not tick inside it
    # (it waits for the GIL after each sleep); released, it ticks about every
    # millisecond. Ten ticks is far below that and far above zero.
    assert middle - start > 0.05 and end - middle > 0.05
    assert sum(start < x < middle for x in ticks) >= 10  # synth
    assert sum(middle < x < end for x in ticks) >= 10    # read_events + run
