#!/usr/bin/env bash
# Guards the main job: runs scripts/main_job.sh — the steps `./setup.sh run` takes — at
# small sizes in an empty directory, then a second time over the results the first run
# left, and fails when a step fails, the report is missing or the end of the output does
# not give the comparisons' summary and the report's path.
# With KEEP, the results are moved there afterwards: the local run the Slurm sweep test
# compares against (every experiment at quick size, run by `gilab experiment all`).
#   tests/main_job_test.sh GILAB SOURCE_DIR [KEEP]
set -euo pipefail
gilab="$1"
source_dir="$2"
keep="${3:-}"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
cd "$work"

for run in first second; do
  log="$work/$run.log"
  if ! bash "$source_dir/scripts/main_job.sh" "$gilab" --small >"$log" 2>&1; then
    tail -n 60 "$log"
    echo "main job: the $run run failed (last lines above)"
    exit 1
  fi
  if [ ! -s results/report.html ]; then
    echo "main job: the $run run wrote no results/report.html"
    exit 1
  fi
  tail_lines="$(tail -n 8 "$log")"
  for expected in "comparisons against the path-traced reference" "open $work/results/report.html"; do
    if ! grep -qF "$expected" <<<"$tail_lines"; then
      printf '%s\n' "$tail_lines"
      echo "main job: the $run run does not end with '$expected'"
      exit 1
    fi
  done
  # One line per compared technique, each naming its frame time, relMSE and FLIP.
  for technique in path photon vct; do
    if ! grep -qE "^  $technique +cornell [0-9.e+-]+ ms, relMSE [0-9.e+-]+, FLIP [0-9.e+-]+" <<<"$tail_lines"; then
      printf '%s\n' "$tail_lines"
      echo "main job: the $run run's summary has no line for $technique"
      exit 1
    fi
  done
done
if [ -n "$keep" ]; then
  rm -rf "$keep"
  mkdir -p "$(dirname "$keep")"
  mv "$work/results" "$keep"
fi
echo "main job: both runs ended with the report and the summary"
