#!/usr/bin/env bash
# Builds the libFuzzer targets of tests/fuzz with Debian's clang (address and
# undefined sanitizers, libFuzzer) in build-fuzz/, writes their seed corpora
# with the project's writers, runs every target for SECONDS each and prints a
# table: target, executions, crashes, timeouts, peak RSS.
#   scripts/fuzz.sh [SECONDS_PER_TARGET] [TARGET...]     (default 30 s, every target)
# Environment: CELC_FUZZ_BUILD_DIR (default build-fuzz), CELC_JOBS (default nproc),
#   CELC_FUZZ_RSS_MB (default 1024), CELC_FUZZ_MALLOC_MB (default 64: no single
#   allocation above 64 MB), CELC_FUZZ_TIMEOUT (default 10 s per input).
# The corpus grows in BUILD/fuzz-corpus/<target> across runs (the long campaign:
# run it again with a larger SECONDS); findings go to BUILD/fuzz-artifacts/<target>/
# (reproduce: BUILD/tests/fuzz/fuzz_<target> FILE).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
seconds="${1:-30}"
shift || true
build="${CELC_FUZZ_BUILD_DIR:-$root/build-fuzz}"
rss="${CELC_FUZZ_RSS_MB:-1024}"
malloc_mb="${CELC_FUZZ_MALLOC_MB:-64}"
timeout_s="${CELC_FUZZ_TIMEOUT:-10}"
all_targets=(events_text rpg_sequence calibration config_yaml aedat2 aedat31 aedat4_none aedat4_lz4 aedat4_zstd)
targets=("$@")
[ "${#targets[@]}" -eq 0 ] && targets=("${all_targets[@]}")

# clang with libFuzzer (Debian: clang, and libclang-rt-<version>-dev for the runtime)
need=()
command -v clang++ >/dev/null || need+=(clang)
if [ "${#need[@]}" -gt 0 ] || ! ls /usr/lib/llvm-*/lib/clang/*/lib/linux/libclang_rt.fuzzer-x86_64.a >/dev/null 2>&1; then
  sudo_cmd=()
  [ "$(id -u)" -ne 0 ] && sudo_cmd=(sudo)
  "${sudo_cmd[@]}" apt-get update -qq
  DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends clang >&2
  version="$(clang++ --version | sed -n 's/.*clang version \([0-9]*\).*/\1/p' | head -1)"
  DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends \
    "libclang-rt-${version}-dev" >&2
fi

launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
CC=clang CXX=clang++ cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release -DCELC_FUZZ=ON \
  -DCELC_BUILD_TESTS=OFF -DCELC_BUILD_BENCHMARKS=OFF "${launcher[@]}" >&2
cmake --build "$build" --target celc_fuzz -j "${CELC_JOBS:-$(nproc)}" >&2

seeds="$build/fuzz-seeds"
rm -rf "$seeds"
"$build/tests/fuzz/celc_fuzz_seeds" "$seeds" >&2

dict_of() {
  case "$1" in
    aedat2) echo "$root/tests/fuzz/aedat2.dict" ;;
    aedat31) echo "$root/tests/fuzz/aedat31.dict" ;;
    aedat4_*) echo "$root/tests/fuzz/aedat4.dict" ;;
    *) echo "$root/tests/fuzz/text.dict" ;;
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
  echo "fuzz: $t for $seconds s" >&2
  set +e
  ASAN_OPTIONS="${ASAN_OPTIONS:-allocator_may_return_null=0:detect_leaks=1}" \
  UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}" \
    "$build/tests/fuzz/fuzz_$t" -max_total_time="$seconds" -rss_limit_mb="$rss" -malloc_limit_mb="$malloc_mb" \
    -timeout="$timeout_s" -max_len=65536 -dict="$(dict_of "$t")" -print_final_stats=1 \
    -artifact_prefix="$artifacts/" "$corpus" "$seeds/$t" >"$log" 2>&1
  rc=$?
  set -e
  execs="$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)"
  peak="$(sed -n 's/^stat::peak_rss_mb: *//p' "$log" | tail -1)"
  new=$(( $(ls "$artifacts" | wc -l) - before ))
  timeouts="$(ls -t "$artifacts" | head -n "$new" | grep -c '^timeout-' || true)"
  crashes=$(( new - timeouts ))
  if [ "$rc" -ne 0 ] && [ "$new" -eq 0 ]; then crashes=$(( crashes + 1 )); fi
  [ "$crashes" -ne 0 ] || [ "$timeouts" -ne 0 ] && status=1
  rows+=("$(printf '| %-13s | %12s | %7s | %8s | %11s |' "$t" "${execs:-?}" "$crashes" "$timeouts" "${peak:-?} MB")")
done

echo "| target        |   executions | crashes | timeouts | peak RSS    |"
echo "|---------------|--------------|---------|----------|-------------|"
printf '%s\n' "${rows[@]}"
echo "($seconds s per target, -rss_limit_mb=$rss -malloc_limit_mb=$malloc_mb -timeout=$timeout_s; logs in $build/fuzz-<target>.log)"
exit "$status"
