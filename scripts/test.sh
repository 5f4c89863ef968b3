#!/usr/bin/env bash
# Every test: installs what is missing, checks the formatting, builds, runs the test suite, runs the
# CPU tests again under AddressSanitizer + UndefinedBehaviorSanitizer, and runs each fuzz target for
# a bounded time over its corpus. Set CRISP_FUZZ_SECONDS to change that time (default 20 per target).
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/setup.sh
jobs=$(nproc 2>/dev/null || echo 2)

echo "== format (.clang-format)"
./scripts/check_format.sh
echo "== build"
./scripts/build.sh build
echo "== tests"
ctest --test-dir build --output-on-failure -j "$jobs"

echo "== sanitizer build (ASan + UBSan)"
./scripts/build.sh build-sanitize -DCRISP_SANITIZE=ON -DCMAKE_BUILD_TYPE=Debug
echo "== CPU tests under the sanitizers"
ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  ctest --test-dir build-sanitize --output-on-failure -j "$jobs" -L cpu

echo "== fuzz targets (libFuzzer, clang, ASan + UBSan)"
if [ ! -f build-fuzz/CMakeCache.txt ]; then
  CC=clang CXX=clang++ cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCRISP_FUZZ=ON \
    -DCRISP_BUILD_TESTS=OFF -DCRISP_BUILD_TOOLS=OFF -DCRISP_BUILD_EXAMPLES=OFF -DCRISP_INSTALL=OFF >/dev/null
fi
cmake --build build-fuzz -j "$jobs"
seconds=${CRISP_FUZZ_SECONDS:-20}
for target in build-fuzz/fuzz/fuzz_*; do
  name=$(basename "$target")
  corpus=fuzz/corpus/${name#fuzz_}
  work=$(mktemp -d)
  echo "-- $name: ${seconds}s over $corpus"
  "$target" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -print_final_stats=0 \
    -artifact_prefix="build-fuzz/$name-" "$work" "$corpus" 2>&1 | tail -n 2
  rm -rf "$work"
done
echo "== all tests passed"
