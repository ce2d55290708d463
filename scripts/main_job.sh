#!/usr/bin/env bash
# The main job: what `./setup.sh run` does after building, and what the main-job test runs
# in an empty directory (tests/main_job_test.sh), so the two cannot drift apart.
#
#   scripts/main_job.sh GILAB [--small]
#
# Runs in the current directory and writes ./results: the stereo Cornell box with the
# path tracer, every experiment at quick size, the path tracer, photon mapping and VCT
# compared on the Cornell box and on Sponza, then the report; it ends by printing the
# comparisons' summary and the report's path. --small shrinks the render and the
# comparisons (the steps stay the same) for the test.
set -euo pipefail
if [ $# -lt 1 ] || [ $# -gt 2 ] || { [ $# -eq 2 ] && [ "$2" != "--small" ]; }; then
  echo "usage: $0 GILAB [--small]" >&2
  exit 2
fi
gilab="$1"
small="${2:-}"

render_size=(--spp 16)
compare_size=()
if [ -n "$small" ]; then
  render_size=(--spp 2 -W 32 -H 32)
  compare_size=(-W 32 -H 32 --reference-spp 16 --frames 1)
fi

step() { echo; echo "== main job: $*"; }

mkdir -p results/render
step "stereo Cornell box with the path tracer"
"$gilab" render cornell --hmd vive "${render_size[@]}" --output results/render/cornell_stereo

# --resume: a second run (after an interruption, or simply again) keeps what this same
# build already finished with the same settings and redoes the rest.
step "every experiment at quick size"
"$gilab" experiment all --quick --resume

# A scene whose shared meshes are missing is skipped with the loader's message.
for scene in cornell sponza; do
  step "path tracer, photon mapping and VCT on $scene"
  if problem="$("$gilab" info "$scene" 2>&1 >/dev/null)"; then
    "$gilab" compare "$scene" -t path,photon,vct "${compare_size[@]}"
  else
    echo "main job: skipping the $scene comparison: $problem"
  fi
done

step "report"
"$gilab" report
echo "main job: results are in $(pwd)/results; open $(pwd)/results/report.html"
