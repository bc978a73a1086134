#!/usr/bin/env bash
# The whole test suite under AddressSanitizer and UndefinedBehaviorSanitizer (g++): builds
# build-asan with both on every target and runs ctest there; any report fails its test.
# Slow (about three times the plain suite): not part of CI; run it before a release and after
# changes to readers or memory handling. Extra arguments go to ctest (e.g. -R Cli).
#   bash tools/sanitize.sh [ctest arguments]
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${ASAN_BUILD_DIR:-$root/build-asan}"
bash "$root/tools/setup.sh" packages
flags="-fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer -g"
# No Python module: an ASan-built extension needs the ASan runtime preloaded into python3.
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_FLAGS="$flags" \
  -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" -DSCALLOP_BUILD_PYTHON=OFF >/dev/null
cmake --build "$build" -j "${JOBS:-$(nproc)}"
# detect_leaks: OpenCASCADE keeps singletons to the end; the tests own no raw memory.
export ASAN_OPTIONS="detect_leaks=0:abort_on_error=1:detect_stack_use_after_return=0"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
cd "$build" && ctest --output-on-failure -j "${JOBS:-$(nproc)}" "$@"
