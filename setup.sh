#!/usr/bin/env bash
# Installs what is missing (Debian 12 packages), builds gilab in Release, then:
#   ./setup.sh run    the main job (scripts/main_job.sh): renders the stereo Cornell box,
#                     runs the quick experiments, compares the techniques on the Cornell
#                     box and Sponza, writes the report and prints its path and a summary
#   ./setup.sh test   runs the whole test suite (CTest), then again built with the
#                     address and undefined-behaviour sanitizers (build-sanitize/),
#                     leaving out the tests labelled heavy
#   ./setup.sh build  only builds
set -euo pipefail
cd "$(dirname "$0")"
mode="${1:-build}"
case "$mode" in run|test|build) ;; *) echo "usage: $0 [run|test|build]" >&2; exit 2 ;; esac

packages=(
  cmake ninja-build g++ ccache git pkg-config
  libembree-dev libtbb-dev libglm-dev libtinygltf-dev libtinyobjloader-dev
  libcgal-dev libgmp-dev libmpfr-dev libopenexr-dev libimath-dev libstb-dev
  libopenvdb-dev libboost-iostreams-dev liboctomap-dev nlohmann-json3-dev libcli11-dev
  libgtest-dev libgmock-dev libbenchmark-dev libnanoflann-dev
  gnuplot-nox chromium
  python3-dev pybind11-dev python3-numpy python3-pytest python3-matplotlib
  # the single-node Slurm that the sweep_slurm test starts (scripts/slurm_local.sh)
  slurm-wlm munge
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
# Through ccache: a second run rebuilds only what changed, and the sanitizer pass reuses the
# release build's objects for the code it compiles the same way (CMakeLists.txt,
# gilab_sanitized). With paths made relative to the checkout, both build folders hash alike;
# depend mode takes the headers from the compiler's dependency file instead of running the
# preprocessor once more on every file it has not seen.
export CCACHE_BASEDIR="$(pwd)" CCACHE_DEPEND=1
cmake_common=(-G Ninja -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
cmake -S . -B build "${cmake_common[@]}"
cmake --build build -j "$jobs"

case "$mode" in
  run)
    # The main job's steps live in one script, which the test suite also runs (main_job).
    scripts/main_job.sh "$(pwd)/build/gilab"
    ;;
  test)
    ctest --test-dir build --output-on-failure --no-tests=error -j "$jobs"
    # The suite again, with gilab's libraries built with AddressSanitizer and UBSan at -O1
    # (a finding fails its test; the tests' own code and the per-paper experiment
    # definitions are built as in the release build), without the tests labelled heavy
    # (the whole experiments at quick size and the every-shipped-scene renders, which the
    # sanitizers slow about tenfold), slurm and browser (they start the Slurm daemons and
    # Chromium, which no sanitizer build changes; the sweep and report code they drive runs
    # sanitized in the sweep and report tests). Of the interrupted-batch tests it keeps the
    # SIGINT one: SIGTERM takes the same handler, and after SIGKILL no gilab code runs, so
    # those (and the killed rerun) check files that the release pass checks just as well.
    cmake -S . -B build-sanitize "${cmake_common[@]}" -DGILAB_SANITIZE=ON -DGILAB_BUILD_BENCHMARKS=OFF
    cmake --build build-sanitize -j "$jobs"
    ctest --test-dir build-sanitize --output-on-failure --no-tests=error -j "$jobs" -LE "heavy|slurm|browser" \
      -E 'ExperimentResume\.(KilledRerun|Interrupted.*/TERM|Interrupted.*/KILL)'
    ;;
esac
