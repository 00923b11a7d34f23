#!/usr/bin/env bash
# README command 2: set up, build, and run the whole default test suite.
#  1. the hostile-input, repair and loader tests under AddressSanitizer + UBSan;
#  2. every test not labelled `slow` in the release build (run last, so its summary
#     is the closing line). Slow tests: `ctest --preset slow`.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
echo "== sanitizer build (ASan + UBSan)"
cmake --preset asan > build-asan-configure.log 2>&1 || { cat build-asan-configure.log; exit 1; }
cmake --build --preset asan
ctest --preset asan
echo "== release build"
cmake --preset default > build-configure.log 2>&1 || { cat build-configure.log; exit 1; }
cmake --build --preset default
ctest --preset default
