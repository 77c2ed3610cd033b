#!/usr/bin/env bash
# The whole test suite, as the README and CI run it:
#   1. install the Debian packages valo needs (only those missing);
#   2. a Release build with -Werror in build/, then every ctest test;
#   3. with CI=true (or --sanitize): an ASan+UBSan build in build-asan/ running every
#      test except the long `reference` and `slow` ones;
#   4. with CI=true (or --fuzz): the libFuzzer harnesses built with clang 14 under
#      ASan+UBSan in build-fuzz/, each fuzzed from a fixed seed for a fixed number of
#      runs (25-45 s each on a quiet machine; at most VALO_FUZZ_SECONDS, default 45).
# VALO_TEST_FULL=1 runs the statistical tests in their full (10x larger) form.
set -euo pipefail
cd "$(dirname "$0")/.."
sanitize=0
fuzz=0
[ "${CI:-}" = "true" ] && sanitize=1 && fuzz=1
for a in "$@"; do
  [ "$a" = "--sanitize" ] && sanitize=1
  [ "$a" = "--fuzz" ] && fuzz=1
done
scripts/install-deps.sh --optional
jobs=$(nproc)
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DVALO_WERROR=ON
cmake --build build -j"$jobs"
(cd build && ctest --output-on-failure -j"$jobs" --timeout 1500)
if [ "$sanitize" = 1 ]; then
  cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DVALO_WERROR=ON -DVALO_SANITIZE=ON
  cmake --build build-asan -j"$jobs"
  (cd build-asan && ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
     ctest --output-on-failure -j"$jobs" -LE "reference|slow" --timeout 1500)
fi
if [ "$fuzz" = 1 ]; then
  if ! command -v clang-14 >/dev/null; then
    echo "valo: clang-14 is missing: the fuzz harnesses cannot be built" >&2
    exit 1
  fi
  rm -rf build-fuzz/fuzz-corpus # the same start as any other run of this commit (configure makes it anew)
  CC=clang-14 cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo -DVALO_WERROR=ON -DVALO_SANITIZE=ON -DVALO_FUZZ=ON \
    -DVALO_FUZZ_SECONDS="${VALO_FUZZ_SECONDS:-45}"
  cmake --build build-fuzz -j"$jobs" --target fuzzers
  (cd build-fuzz && UBSAN_OPTIONS=print_stacktrace=1 ctest --output-on-failure -j"$jobs" -L fuzz)
fi
