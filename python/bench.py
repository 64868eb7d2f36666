#!/usr/bin/env python3
"""Benchmarks of the celc Python module (figures in docs/python.md).

  PYTHONPATH=build/python /usr/bin/python3 python/bench.py [--events N] [--dir DIR] [--repeat R]

1. Readers: N events (default 10,000,000) written by the library's own
   writers (celc.write_events) in each format they write, then read with
   celc.read_events; the median of R reads, against the 1 s target.
2. solve(): on a simulated window of 1,000 events (5 lines x 200), the
   wall time of celc.solve from Python against the time spent inside the C++
   call (measured around it in the binding), per method set; median of runs.
"""
import argparse
import os
import statistics
import sys
import tempfile
import time

import numpy as np

import celc


def make_events(n, width=346, height=260, seed=1):
    """n events on integer pixels at increasing whole-microsecond times."""
    rng = np.random.default_rng(seed)
    ev = np.empty(n, dtype=celc.EVENT_DTYPE)
    ev["t"] = np.cumsum(rng.integers(0, 3, n)) * 1e-6  # ~1 M events/s
    ev["x"] = rng.integers(0, width, n)
    ev["y"] = rng.integers(0, height, n)
    ev["p"] = rng.random(n) < 0.5
    return ev


def bench_readers(n, directory, repeat):
    ev = make_events(n)
    rows = []
    for fmt, ext, kw in [("aedat2", "aedat", {"chip": "DAVIS346"}),
                         ("aedat31", "aedat", {"chip": "DAVIS346"}),
                         ("aedat4", "aedat4", {"compression": "lz4"}),
                         ("aedat4", "aedat4", {"compression": "zstd"}),
                         ("text", "txt", {})]:
        label = fmt + (f" ({kw['compression']})" if "compression" in kw else "")
        path = os.path.join(directory, f"bench_{fmt}_{kw.get('compression', '')}.{ext}")
        celc.write_events(path, ev, format=fmt, **kw)
        times = []
        for _ in range(repeat):
            start = time.perf_counter()
            back = celc.read_events(path)
            times.append(time.perf_counter() - start)
            assert len(back) == n
            del back
        size_mb = os.path.getsize(path) / 1e6
        os.remove(path)
        rows.append((label, size_mb, statistics.median(times)))
    return rows


def bench_solve(repeat):
    w = celc.simulate_window(seed=1, n_lines=5, events_per_line=200, event_noise_px=1.0)
    assert len(w["events"]) == 1000
    rows = []
    for methods in (["celc"], ["celc", "celc_opt"], ["celc", "celc_opt", "celc_ml", "ce3lc", "npt"]):
        wall, cpp = [], []
        for _ in range(repeat):
            start = time.perf_counter()
            _, inside = celc._solve_timed(w["events"], w["labels"], w["omega"], w["camera"], methods)
            wall.append(time.perf_counter() - start)
            cpp.append(inside)
        wall_m, cpp_m = statistics.median(wall), statistics.median(cpp)
        rows.append((",".join(methods), wall_m, cpp_m))
    return rows


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--events", type=int, default=10_000_000)
    ap.add_argument("--dir", default=None, help="where the files are written (default: a temporary folder)")
    ap.add_argument("--repeat", type=int, default=3, help="reads per format")
    ap.add_argument("--solve-repeat", type=int, default=200, help="solve() calls per method set")
    a = ap.parse_args()

    print(f"celc {celc.__version__}, python {sys.version.split()[0]}, numpy {np.__version__}, "
          f"{os.cpu_count()} cores, load {os.getloadavg()[0]:.1f}\n")
    with tempfile.TemporaryDirectory(dir=a.dir) as d:
        rows = bench_readers(a.events, d, a.repeat)
    print(f"read_events, {a.events:,} events (median of {a.repeat}; target <= 1 s)\n")
    print("| format | file [MB] | seconds | M events/s | <= 1 s |")
    print("|---|---|---|---|---|")
    for label, size_mb, t in rows:
        print(f"| {label} | {size_mb:.0f} | {t:.3f} | {a.events / t / 1e6:.1f} | {'yes' if t <= 1.0 else 'no'} |")

    rows = bench_solve(a.solve_repeat)
    print(f"\nsolve() on 1,000 events (5 lines x 200; median of {a.solve_repeat}; target overhead <= 5%)\n")
    print("| methods | Python call [ms] | C++ call [ms] | overhead [us] | overhead |")
    print("|---|---|---|---|---|")
    for methods, wall, cpp in rows:
        print(f"| {methods} | {wall * 1e3:.3f} | {cpp * 1e3:.3f} | {(wall - cpp) * 1e6:.1f} | "
              f"{100 * (wall - cpp) / cpp:.2f}% |")


if __name__ == "__main__":
    main()
