#!/usr/bin/env bash
# Builds and runs the Google Benchmark binary and prints a table of medians.
#   scripts/bench.sh [benchmark filter regex]
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
"$root/scripts/setup.sh"
build="${CELC_BUILD_DIR:-$root/build}"
json="$(mktemp)"
"$build/celc_bench" --benchmark_filter="${1:-.}" --benchmark_repetitions=5 \
  --benchmark_report_aggregates_only=true --benchmark_format=json --benchmark_out="$json" \
  --benchmark_out_format=json > /dev/null
/usr/bin/python3 - "$json" <<'PY'
import json, sys
data = json.load(open(sys.argv[1]))
print("| benchmark | median | unit | counters |")
print("|---|---|---|---|")
for b in data["benchmarks"]:
    if b.get("aggregate_name") != "median":
        continue
    extra = ", ".join(f"{k}={v:.3g}" for k, v in b.items()
                      if k not in ("name", "run_name", "run_type", "repetitions", "threads",
                                   "aggregate_name", "aggregate_unit", "iterations", "real_time",
                                   "cpu_time", "time_unit", "family_index",
                                   "per_family_instance_index", "repetition_index")
                      and isinstance(v, (int, float)))
    print(f"| {b['run_name']} | {b['real_time']:.3g} | {b['time_unit']} | {extra} |")
PY
rm -f "$json"
