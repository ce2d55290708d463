#!/usr/bin/env bash
# Installs what is missing (Debian 12 packages), builds gilab in Release, then:
#   ./setup.sh run    renders the stereo Cornell box and runs the quick experiments
#   ./setup.sh test   runs the whole test suite (CTest)
#   ./setup.sh build  only builds
set -euo pipefail
cd "$(dirname "$0")"
mode="${1:-build}"
case "$mode" in run|test|build) ;; *) echo "usage: $0 [run|test|build]" >&2; exit 2 ;; esac

packages=(
  cmake ninja-build g++ git pkg-config
  libembree-dev libtbb-dev libglm-dev libtinygltf-dev libtinyobjloader-dev
  libcgal-dev libgmp-dev libmpfr-dev libopenexr-dev libimath-dev libstb-dev
  libopenvdb-dev libboost-iostreams-dev liboctomap-dev nlohmann-json3-dev libcli11-dev
  libgtest-dev libgmock-dev libbenchmark-dev libnanoflann-dev
  gnuplot-nox
)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing ${missing[*]}"
  sudo_cmd=""
  [ "$(id -u)" -eq 0 ] || sudo_cmd="sudo"
  $sudo_cmd apt-get update -q
  DEBIAN_FRONTEND=noninteractive $sudo_cmd apt-get install -y -q --no-install-recommends "${missing[@]}"
fi

jobs="$(nproc)"
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release
cmake --build build -j "$jobs"

case "$mode" in
  run)
    ./build/gilab render cornell --hmd vive --spp 16 --output results/render/cornell_stereo
    ./build/gilab experiment all --quick
    ./build/gilab report
    echo "setup: results are in $(pwd)/results"
    ;;
  test)
    ctest --test-dir build --output-on-failure --no-tests=error -j "$jobs"
    ;;
esac
