#!/usr/bin/env bash
# The unit tests under AddressSanitizer and UndefinedBehaviorSanitizer (UBSan
# without recovery: the first undefined behaviour fails the test).
#   scripts/test_sanitize.sh [extra ctest args...]
#       every test: a second GCC build directory (CELC_ASAN_BUILD_DIR, default
#       build-asan), RelWithDebInfo, then ctest there (about an hour cold on
#       2 cores: docs/robustness.md)
#   scripts/test_sanitize.sh --subset [extra gtest args...]
#       what CI runs: the tests of the readers, calibration and config files
#       and the window source (celc_sanitize_tests, tests/fuzz/CMakeLists.txt
#       lists them) built by clang with the instrumented library of the fuzz
#       targets (scripts/fuzz.sh --build-only, CELC_FUZZ_BUILD_DIR, default build-fuzz)
# Environment: CELC_JOBS (default nproc).
# Benchmarks are not built.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
jobs="${CELC_JOBS:-$(nproc)}"
# Leak checking stays on; OpenCV / PCL keep process-lifetime caches that LSan
# does not report as leaks. halt_on_error makes every report fail its test.
export ASAN_OPTIONS="${ASAN_OPTIONS:-halt_on_error=1:detect_leaks=1:abort_on_error=0}"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}"
start=$(date +%s)

if [ "${1:-}" = "--subset" ]; then
  shift
  build="${CELC_FUZZ_BUILD_DIR:-$root/build-fuzz}"
  CELC_FUZZ_BUILD_DIR="$build" "$root/scripts/fuzz.sh" --build-only
  built=$(date +%s)
  set +e
  (cd "$root" && "$build/tests/fuzz/celc_sanitize_tests" --gtest_brief=1 "$@")
  rc=$?
  set -e
  end=$(date +%s)
  echo "test_sanitize: build $((built - start)) s, tests $((end - built)) s, exit $rc (subset: celc_sanitize_tests)" >&2
  exit "$rc"
fi

build="${CELC_ASAN_BUILD_DIR:-$root/build-asan}"
flags="-fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer"
launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCELC_BUILD_BENCHMARKS=OFF \
  -DCMAKE_CXX_FLAGS="$flags" -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" \
  -DCMAKE_SHARED_LINKER_FLAGS="-fsanitize=address,undefined" "${launcher[@]}" >&2
cmake --build "$build" -j "$jobs" >&2
built=$(date +%s)
set +e
(cd "$build" && ctest -j "$jobs" --output-on-failure "$@")
rc=$?
set -e
end=$(date +%s)
echo "test_sanitize: build $((built - start)) s, tests $((end - built)) s, exit $rc" >&2
exit "$rc"
