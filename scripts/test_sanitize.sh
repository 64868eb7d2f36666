#!/usr/bin/env bash
# Builds the unit tests with AddressSanitizer and UndefinedBehaviorSanitizer
# (UBSan without recovery: the first undefined behaviour fails the test) in a
# second build directory, then runs ctest there.
#   scripts/test_sanitize.sh [extra ctest args...]
# Environment: CELC_ASAN_BUILD_DIR (default build-asan), CELC_JOBS (default nproc).
# Benchmarks are not built. The compiler is the default one (GCC on Debian 12).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${CELC_ASAN_BUILD_DIR:-$root/build-asan}"
jobs="${CELC_JOBS:-$(nproc)}"
flags="-fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer"
launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
start=$(date +%s)
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCELC_BUILD_BENCHMARKS=OFF \
  -DCMAKE_CXX_FLAGS="$flags" -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" \
  -DCMAKE_SHARED_LINKER_FLAGS="-fsanitize=address,undefined" "${launcher[@]}" >&2
cmake --build "$build" -j "$jobs" >&2
built=$(date +%s)
# Leak checking stays on; OpenCV / PCL keep process-lifetime caches that LSan
# does not report as leaks. halt_on_error makes every report fail its test.
export ASAN_OPTIONS="${ASAN_OPTIONS:-halt_on_error=1:detect_leaks=1:abort_on_error=0}"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}"
set +e
(cd "$build" && ctest -j "$jobs" --output-on-failure "$@")
rc=$?
set -e
end=$(date +%s)
echo "test_sanitize: build $((built - start)) s, tests $((end - built)) s, exit $rc" >&2
exit "$rc"
