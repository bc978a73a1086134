#!/usr/bin/env bash
# Fuzzes every reader of scallop with libFuzzer (Debian's clang 14 and libclang-rt-14-dev):
# builds build-fuzz (the core library and fuzz/*_fuzz.cpp instrumented for coverage, with
# AddressSanitizer and UBSan), then runs each target for SECONDS (default 60) from the seeds in
# fuzz/seeds/<reader>/, one input at most 2 s and 2 GB. A crash, a sanitizer report, an
# exception other than scallop::Error or a slow input stops the run with the input saved as
# build-fuzz/<reader>-crash-* (or timeout-*, oom-*); the exit status is then non-zero.
#   bash tools/fuzz.sh [SECONDS]
set -euo pipefail
seconds="${1:-60}"
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${FUZZ_BUILD_DIR:-$root/build-fuzz}"
missing=()
for p in clang-14 libclang-rt-14-dev cmake nlohmann-json3-dev libfmt-dev libboost-dev libpolyclipping-dev libqhull-dev; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ "${#missing[@]}" -gt 0 ]; then
  if [ "$(id -u)" -eq 0 ]; then sudo=(); else sudo=(sudo); fi
  "${sudo[@]}" apt-get update -qq
  DEBIAN_FRONTEND=noninteractive "${sudo[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi
flags="-fsanitize=address,undefined,fuzzer-no-link -fno-sanitize-recover=undefined -fno-omit-frame-pointer -g"
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release -DCMAKE_C_COMPILER=clang-14 -DCMAKE_CXX_COMPILER=clang++-14 \
  -DCMAKE_CXX_FLAGS="$flags" -DSCALLOP_BUILD_CAD=OFF -DSCALLOP_BUILD_CLI=OFF -DSCALLOP_BUILD_TESTS=OFF \
  -DSCALLOP_BUILD_BENCH=OFF -DSCALLOP_INSTALL=OFF -DSCALLOP_BUILD_PYTHON=OFF -DSCALLOP_BUILD_FUZZERS=ON >/dev/null
cmake --build "$build" -j "${JOBS:-$(nproc)}"
status=0
for reader in chain surface stl gcode; do
  corpus="$build/corpus-$reader"
  mkdir -p "$corpus"
  echo "fuzz: $reader for ${seconds} s" >&2
  (cd "$build" && "./fuzz/scallop-fuzz-$reader" -max_total_time="$seconds" -timeout=2 -rss_limit_mb=2048 \
     -artifact_prefix="$build/$reader-" -print_final_stats=1 "$corpus" "$root/fuzz/seeds/$reader" \
     2> "$build/$reader.log") || { status=1; echo "fuzz: $reader FAILED (see $build/$reader.log)" >&2; }
  grep -E "^Done|^stat::new_units_added|^stat::slowest_unit_time_sec" "$build/$reader.log" | tr '\n' ' ' >&2; echo >&2
done
exit "$status"
