#!/usr/bin/env bash
# Builds the libFuzzer targets of tests/fuzz with Debian's clang (address and
# undefined sanitizers, libFuzzer) in build-fuzz/, writes their seed corpora
# with the project's writers, runs every target for SECONDS each, one process
# at a time, and prints a table: target, executions, exec/s, crashes, timeouts,
# peak RSS. Exit status 1 when any target crashed or timed out.
#   scripts/fuzz.sh [SECONDS_PER_TARGET] [TARGET...]     (default 30 s, every target)
#   scripts/fuzz.sh --build-only                          (install, build, seeds; no run)
#   scripts/fuzz.sh --ci [TARGET...]                      (CI: a fixed number of executions per
#        target, about 20 s each on this machine, with libFuzzer's seed 1 unless CELC_FUZZ_SEED
#        says otherwise: the same mutations every time, so that a CI run repeats)
# Environment: CELC_FUZZ_BUILD_DIR (default build-fuzz), CELC_JOBS (default nproc),
#   CELC_FUZZ_RSS_MB (default 1024), CELC_FUZZ_MALLOC_MB (default 64: no single
#   allocation above 64 MB), CELC_FUZZ_TIMEOUT (default 10 s per input),
#   CELC_FUZZ_NICE (default 0: the nice level of the fuzzer processes),
#   CELC_FUZZ_SEED (default 0: libFuzzer picks one; CI sets 1, so that its run
#   repeats the same mutations).
# The corpus grows in BUILD/fuzz-corpus/<target> across runs (the long campaign:
# run it again with a larger SECONDS; docs/robustness.md); findings go to
# BUILD/fuzz-artifacts/<target>/ (reproduce: BUILD/tests/fuzz/fuzz_<target> FILE).
# The build also makes celc_sanitize_tests (scripts/test_sanitize.sh --subset).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build_only=0
if [ "${1:-}" = "--build-only" ]; then
  build_only=1
  shift
fi
ci_runs=0
if [ "${1:-}" = "--ci" ]; then
  ci_runs=1
  shift
  export CELC_FUZZ_SEED="${CELC_FUZZ_SEED:-1}"
  seconds=0
else
  seconds="${1:-30}"
  shift || true
fi
build="${CELC_FUZZ_BUILD_DIR:-$root/build-fuzz}"
rss="${CELC_FUZZ_RSS_MB:-1024}"
malloc_mb="${CELC_FUZZ_MALLOC_MB:-64}"
timeout_s="${CELC_FUZZ_TIMEOUT:-10}"
nice_level="${CELC_FUZZ_NICE:-0}"
all_targets=(events_text rpg_sequence calibration config_yaml aedat2 aedat31 aedat4_none aedat4_lz4 aedat4_zstd
             rosbag hdf5)
targets=("$@")
[ "${#targets[@]}" -eq 0 ] && targets=("${all_targets[@]}")

# clang with libFuzzer (Debian: clang, and libclang-rt-<version>-dev for the
# runtime); the bag seeds come from celc_make_fixtures, built here too.
sudo_cmd=()
[ "$(id -u)" -ne 0 ] && sudo_cmd=(sudo)
apt_install() {
  "${sudo_cmd[@]}" apt-get update -qq
  DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "$@" >&2
}
if ! command -v clang++ >/dev/null || ! ls /usr/lib/llvm-*/lib/clang/*/lib/linux/libclang_rt.fuzzer-x86_64.a >/dev/null 2>&1; then
  command -v clang++ >/dev/null || apt_install clang
  version="$(clang++ --version | sed -n 's/.*clang version \([0-9]*\).*/\1/p' | head -1)"
  apt_install "libclang-rt-${version}-dev"
fi

launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
CC=clang CXX=clang++ cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release -DCELC_FUZZ=ON \
  -DCELC_BUILD_TESTS=OFF -DCELC_BUILD_BENCHMARKS=OFF "${launcher[@]}" >&2
build_targets=(celc_fuzz celc_make_fixtures)
grep -q '^celc_sanitize_tests:' "$build/Makefile" 2>/dev/null && build_targets+=(celc_sanitize_tests)
cmake --build "$build" --target "${build_targets[@]}" -j "${CELC_JOBS:-$(nproc)}" >&2

# Seeds: celc_fuzz_seeds, then the bags of celc_make_fixtures from its small sequence.
seeds="$build/fuzz-seeds"
rm -rf "$seeds"
"$build/tests/fuzz/celc_fuzz_seeds" "$seeds" >&2
# (the bags only: the HDF5 seeds come from celc_fuzz_seeds)
bags=(seq_none seq_bz2 seq_lz4 seq_odom bad_truncated bad_unindexed bad_type bad_conn_swapped bad_conn_unknown
      bad_chunk_info_count)
"$build/celc_make_fixtures" "$seeds/bag_sequence" "$seeds/bag_fixtures" "${bags[@]/%/.bag}" >&2
for b in "${bags[@]}"; do
  cp "$seeds/bag_fixtures/$b.bag" "$seeds/rosbag/seed_$b"
done
rm -rf "$seeds/bag_sequence" "$seeds/bag_fixtures"
[ "$build_only" -eq 1 ] && exit 0

dict_of() {
  case "$1" in
    aedat2) echo "$root/tests/fuzz/aedat2.dict" ;;
    aedat31) echo "$root/tests/fuzz/aedat31.dict" ;;
    aedat4_*) echo "$root/tests/fuzz/aedat4.dict" ;;
    rosbag) echo "$root/tests/fuzz/rosbag.dict" ;;
    hdf5) echo "$root/tests/fuzz/hdf5.dict" ;;
    *) echo "$root/tests/fuzz/text.dict" ;;
  esac
}

# Largest input per target: a few times its largest seed. The readers never
# need more (the text reader holds a whole small file in one block either
# way), and small inputs keep each execution short.
max_len_of() {
  case "$1" in
    events_text|rpg_sequence|calibration) echo 4096 ;;
    config_yaml|aedat*) echo 16384 ;;
    *) echo 32768 ;;
  esac
}

# CI's executions per target: about 20 s each at the rates of a fresh corpus on
# this machine (docs/robustness.md); the HDF5 reader gets as many as the
# fewest of the others (15,000: about 15 s), the bag reader 30,000 (about 18 s
# at 1,700 executions/s from its seeds).
ci_runs_of() {
  case "$1" in
    events_text) echo 20000 ;;
    rpg_sequence) echo 25000 ;;
    calibration) echo 15000 ;;
    config_yaml) echo 16000 ;;
    aedat2) echo 100000 ;;
    aedat31) echo 80000 ;;
    aedat4_none) echo 40000 ;;
    aedat4_lz4) echo 80000 ;;
    aedat4_zstd) echo 50000 ;;
    rosbag) echo 30000 ;;
    hdf5) echo 15000 ;;
  esac
}

rows=()
status=0
for t in "${targets[@]}"; do
  corpus="$build/fuzz-corpus/$t"
  artifacts="$build/fuzz-artifacts/$t"
  mkdir -p "$corpus" "$artifacts"
  before="$(ls "$artifacts" | wc -l)"
  log="$build/fuzz-$t.log"
  if [ "$ci_runs" -eq 1 ]; then
    limit=(-runs="$(ci_runs_of "$t")")
    echo "fuzz: $t for $(ci_runs_of "$t") executions" >&2
  else
    limit=(-max_total_time="$seconds")
    echo "fuzz: $t for $seconds s" >&2
  fi
  start=$(date +%s)
  set +e
  LSAN_OPTIONS="${LSAN_OPTIONS:-suppressions=$root/tests/fuzz/lsan.supp}" \
  ASAN_OPTIONS="${ASAN_OPTIONS:-allocator_may_return_null=0:detect_leaks=1}" \
  UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}" \
    nice -n "$nice_level" "$build/tests/fuzz/fuzz_$t" "${limit[@]}" -rss_limit_mb="$rss" \
    -malloc_limit_mb="$malloc_mb" -timeout="$timeout_s" -max_len="$(max_len_of "$t")" -dict="$(dict_of "$t")" \
    -seed="${CELC_FUZZ_SEED:-0}" -print_final_stats=1 -artifact_prefix="$artifacts/" "$corpus" "$seeds/$t" >"$log" 2>&1
  rc=$?
  set -e
  wall=$(( $(date +%s) - start ))
  execs="$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)"
  peak="$(sed -n 's/^stat::peak_rss_mb: *//p' "$log" | tail -1)"
  rate="?"
  [ -n "$execs" ] && [ "$wall" -gt 0 ] && rate=$(( execs / wall ))
  new=$(( $(ls "$artifacts" | wc -l) - before ))
  timeouts="$(ls -t "$artifacts" | head -n "$new" | grep -c '^timeout-' || true)"
  crashes=$(( new - timeouts ))
  if [ "$rc" -ne 0 ] && [ "$new" -eq 0 ]; then crashes=$(( crashes + 1 )); fi
  if [ "$crashes" -ne 0 ] || [ "$timeouts" -ne 0 ]; then status=1; fi
  rows+=("$(printf '| %-13s | %12s | %7s | %7s | %8s | %11s | %6s |' "$t" "${execs:-?}" "$rate" "$crashes" \
            "$timeouts" "${peak:-?} MB" "$wall")")
done

echo "| target        |   executions |  exec/s | crashes | timeouts | peak RSS    | wall s |"
echo "|---------------|--------------|---------|---------|----------|-------------|--------|"
printf '%s\n' "${rows[@]}"
[ "$ci_runs" -eq 1 ] && per="a fixed number of executions per target, seed $CELC_FUZZ_SEED" || per="$seconds s per target"
echo "($per, -rss_limit_mb=$rss -malloc_limit_mb=$malloc_mb -timeout=$timeout_s -max_len 4096-32768;" \
     "logs in $build/fuzz-<target>.log)"
exit "$status"
