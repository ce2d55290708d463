#!/usr/bin/env bash
# Builds the libFuzzer harnesses (clang, address + undefined sanitizers) in build-fuzz/
# and runs each for SECONDS.
#
#   tests/fuzz/run.sh SECONDS [TARGET ...]     targets: obj gltf ply_off scene_json settings
#   FUZZ_JOBS=2 tests/fuzz/run.sh 1800         two targets at a time
#
# Each target starts from tests/fuzz/seeds/TARGET (small hand-made files), the
# regression corpus tests/fuzz/corpus/TARGET, the malformed files of tests/data/bad and
# the matching files of the shared scenes (up to 256 kB each), with the dictionary
# tests/fuzz/dict/TARGET.dict. The growing corpus stays in build-fuzz/corpus/TARGET.
# A crash, leak, timeout (5 s) or out-of-memory input (2 GB) is written to
# build-fuzz/findings/TARGET/ and fuzzing goes on for the whole time (libFuzzer's fork
# mode); once fixed, the input belongs in tests/fuzz/corpus/TARGET/, which
# fuzz_corpus_test replays in the normal suite. The script ends with the
# executions and findings of each target and exits non-zero when there is a finding.
set -euo pipefail
cd "$(dirname "$0")/../.."
seconds="${1:-}"
if ! [[ "$seconds" =~ ^[0-9]+$ ]] || [ "$seconds" -lt 1 ]; then
  echo "usage: tests/fuzz/run.sh SECONDS [target ...]" >&2
  exit 2
fi
shift
all_targets=(obj gltf ply_off scene_json settings)
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=("${all_targets[@]}")
for t in "${targets[@]}"; do
  [[ " ${all_targets[*]} " == *" $t "* ]] || { echo "run.sh: unknown target '$t' (known: ${all_targets[*]})" >&2; exit 2; }
done
# clang and its libFuzzer runtime, besides what ./setup.sh installs.
missing=()
for p in clang libclang-rt-14-dev; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "run.sh: installing ${missing[*]}"
  sudo_cmd=""
  [ "$(id -u)" -eq 0 ] || sudo_cmd="sudo"
  $sudo_cmd apt-get update -q
  DEBIAN_FRONTEND=noninteractive $sudo_cmd apt-get install -y -q --no-install-recommends "${missing[@]}"
fi

build=build-fuzz
launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_C_COMPILER=clang \
  -DCMAKE_CXX_COMPILER=clang++ -DGILAB_FUZZ=ON -DGILAB_BUILD_TESTS=OFF -DGILAB_BUILD_BENCHMARKS=OFF \
  "${launcher[@]}" >/dev/null
cmake --build "$build" -j "$(nproc)" --target $(printf '%s_fuzz ' "${targets[@]}")

shared="$(cd .. && pwd)/shared/scenes"
declare -A extensions=([obj]="obj" [gltf]="gltf glb" [ply_off]="ply off" [scene_json]="json" [settings]="json")

seed_corpus() {  # TARGET → fills $build/corpus/TARGET
  local t="$1" dir="$build/corpus/$1"
  mkdir -p "$dir"
  for src in tests/fuzz/seeds/"$t" tests/fuzz/corpus/"$t"; do
    [ -d "$src" ] && find "$src" -type f -exec cp -n {} "$dir"/ \;
  done
  for ext in ${extensions[$t]}; do
    find tests/data/bad -maxdepth 1 -type f -iname "*.$ext" -exec cp -n {} "$dir"/ \;
  done
  if [ -d "$shared" ]; then
    for ext in ${extensions[$t]}; do
      find "$shared" -type f -iname "*.$ext" -size -256k -print0 |
        while IFS= read -r -d '' f; do cp -n "$f" "$dir/shared_$(basename "$f")"; done
    done
  fi
}

run_target() {  # TARGET → log in $build/logs/TARGET.log
  local t="$1"
  mkdir -p "$build/findings/$t" "$build/logs"
  seed_corpus "$t"
  echo "run.sh: fuzzing $t for $seconds s"
  # Fork mode with the ignore flags keeps fuzzing for the whole time after a finding.
  "$build/tests/fuzz/${t}_fuzz" "$build/corpus/$t" -dict="tests/fuzz/dict/$t.dict" \
    -max_total_time="$seconds" -timeout=5 -rss_limit_mb=2048 -max_len=65536 \
    -fork=1 -ignore_crashes=1 -ignore_timeouts=1 -ignore_ooms=1 \
    -artifact_prefix="$build/findings/$t/" >"$build/logs/$t.log" 2>&1 || true
}

jobs="${FUZZ_JOBS:-1}"
running=0
for t in "${targets[@]}"; do
  run_target "$t" &
  running=$((running + 1))
  if [ "$running" -ge "$jobs" ]; then wait -n; running=$((running - 1)); fi
done
wait

findings=0
printf '%-12s %14s %10s %9s\n' target executions corpus findings
for t in "${targets[@]}"; do
  log="$build/logs/$t.log"
  execs=$(grep -o '^#[0-9]*' "$log" | tr -d '#' | tail -1)
  corpus=$(find "$build/corpus/$t" -type f | wc -l)
  found=$(find "$build/findings/$t" -type f | wc -l)
  findings=$((findings + found))
  printf '%-12s %14s %10s %9s\n' "$t" "${execs:-?}" "$corpus" "$found"
done
if [ "$findings" -gt 0 ]; then
  echo "run.sh: findings are in $build/findings/ (logs in $build/logs/)" >&2
  exit 1
fi
