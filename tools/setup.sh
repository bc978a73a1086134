#!/usr/bin/env bash
# scallop set-up on Debian 12: install what is missing, build, then run the demo or the tests.
#   bash tools/setup.sh demo   # build, then the main job `scallop plan` -> scallop-out/
#   bash tools/setup.sh test   # also installs linuxcnc-uspace; build, then all tests (ctest)
#   bash tools/setup.sh packages  # the test's packages only (tools/sanitize.sh)
# Environment: BUILD_DIR (default build), JOBS (default: number of cores), SCALLOP_WERROR=ON.
set -euo pipefail

mode="${1:-demo}"
case "$mode" in demo|test|build|packages) ;; *) echo "usage: $0 demo|test|build|packages" >&2; exit 2 ;; esac

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${BUILD_DIR:-$root/build}"
jobs="${JOBS:-$(nproc)}"

# Debian packages scallop builds with (headers, CMake configs, test and bench frameworks).
# OpenCASCADE 7.6 reads STEP and IGES (libocct-data-exchange-dev pulls the other OCCT toolkits
# and occt-misc, whose sample parts the tests read); its CMake files name libtbb.so, which only
# libtbb-dev provides (Debian 12's packages do not depend on it).
# python3-pybind11, python3-numpy and python3-dev build the Python module (python/) and run its tests.
packages=(build-essential cmake pkg-config nlohmann-json3-dev libfmt-dev libcli11-dev libboost-dev
          libpolyclipping-dev libqhull-dev libocct-data-exchange-dev libtbb-dev
          libgtest-dev libgmock-dev libbenchmark-dev python3-pybind11 python3-numpy python3-dev)
# The tests check the G-code writer with LinuxCNC's own interpreter, rs274 (gcode_test.cpp
# fails without it). It runs headless; with --no-install-recommends it still pulls in about
# 100 packages (Tcl/Tk, Python, GTK libraries): some 75 MB to download, 255 MB on disk.
if [ "$mode" = test ] || [ "$mode" = packages ]; then packages+=(linuxcnc-uspace); fi
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

if [ "$mode" = packages ]; then exit 0; fi  # tools/sanitize.sh: the test packages only

cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release \
  -DSCALLOP_WERROR="${SCALLOP_WERROR:-OFF}" >/dev/null
cmake --build "$build" -j "$jobs"

case "$mode" in
  demo)
    # The main job: the paper's test surface 1, a 0.25 in ball, 0.001 in scallops, contour
    # paths on the optimal planes -> G-code, report and figures.
    cd "$root" && "$build/scallop" plan --out "$root/scallop-out"
    echo "demo: wrote $root/scallop-out/ (toolpath.ngc, report.json, figures)" ;;
  test)
    cd "$build" && ctest --output-on-failure -j "$jobs" ;;
  build) ;;
esac
