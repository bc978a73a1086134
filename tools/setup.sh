#!/usr/bin/env bash
# scallop set-up on Debian 12: install what is missing, build, then run the demo or the tests.
#   bash tools/setup.sh demo   # build, then `scallop hull` on a built-in chain -> out/
#   bash tools/setup.sh test   # build, then the whole test suite (ctest)
# Environment: BUILD_DIR (default build), JOBS (default: number of cores), SCALLOP_WERROR=ON.
set -euo pipefail

mode="${1:-demo}"
case "$mode" in demo|test|build) ;; *) echo "usage: $0 demo|test|build" >&2; exit 2 ;; esac

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${BUILD_DIR:-$root/build}"
jobs="${JOBS:-$(nproc)}"

# Debian packages scallop builds with (headers, CMake configs, test and bench frameworks).
packages=(build-essential cmake nlohmann-json3-dev libfmt-dev libcli11-dev libboost-dev
          libgtest-dev libgmock-dev libbenchmark-dev)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ "${#missing[@]}" -gt 0 ]; then
  echo "setup: installing ${missing[*]}" >&2
  if [ "$(id -u)" -eq 0 ]; then sudo=(); elif command -v sudo >/dev/null; then sudo=(sudo); else
    echo "setup: missing packages ${missing[*]}; run as root or install them" >&2; exit 1
  fi
  "${sudo[@]}" apt-get update -qq
  DEBIAN_FRONTEND=noninteractive "${sudo[@]}" apt-get install -y -qq --no-install-recommends \
    "${missing[@]}" >/dev/null
fi

cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release \
  -DSCALLOP_WERROR="${SCALLOP_WERROR:-OFF}" >/dev/null
cmake --build "$build" -j "$jobs"

case "$mode" in
  demo)
    mkdir -p "$root/out"
    "$build/scallop" hull --example figure2 --radius 1.0 \
      --json "$root/out/hull.json" --svg "$root/out/hull.svg"
    echo "demo: wrote $root/out/hull.json and $root/out/hull.svg" ;;
  test)
    cd "$build" && ctest --output-on-failure -j "$jobs" ;;
  build) ;;
esac
