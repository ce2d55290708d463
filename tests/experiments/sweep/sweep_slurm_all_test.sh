#!/usr/bin/env bash
# `gilab sweep all --quick --on slurm` on a real single-node Slurm (scripts/slurm_local.sh)
# gives the local run's results: every declared experiment merged with no task missing,
# its tables equal to those of `gilab experiment all --quick` run here (the main job's,
# kept by the main_job test) apart from the columns that measure the run
# (deterministic_tables.py), the same images to the byte, and a report of every experiment.
# Skipped (exit 77) only when the assets are missing or the daemons cannot start.
#   usage: sweep_slurm_all_test.sh GILAB SOURCE_DIR LOCAL_RESULTS
set -euo pipefail
gilab="$1"
source_dir="$2"
local_results="$3"

source "$source_dir/tests/experiments/sweep/slurm_test_lib.sh"
[ -f "$local_results/report.html" ] || fail "no local run in $local_results (the main_job test keeps it there)"
require_assets bunny/stanford-bunny.obj sponza/sponza.obj conference/conference.obj
start_cluster

echo "== gilab sweep all --quick --on slurm"
out="$("$gilab" sweep all --quick --on slurm --batch 4 --results "$work/slurm" 2>&1)" ||
    fail "gilab sweep all --on slurm failed: $out"
echo "$out"
jobs="$(job_ids "$out")"
wait_for_jobs "$jobs" 1200
results="$work/slurm"
[ -f "$results/report.html" ] || { tail -n 20 "$results/.sweep/logs/merge.1.out"; fail "the merge job wrote no report"; }

# Every experiment of the local run (all are declared), merged through Slurm.
merged=0
for dir in "$local_results"/*/; do
    name="$(basename "$dir")"
    [ -f "$dir/results.json" ] || continue
    [ -f "$results/$name/results.json" ] || fail "$name: not merged through Slurm"
    [ "$(json_field "$results/$name/results.json" config effective tasks_missing)" = "[]" ] || fail "$name: tasks missing"
    same_tables "$name" "$local_results" "$results"
    # Images: the tone-mapped PNGs to the byte (the EXRs' headers hold render times).
    for png in "$dir"*.png; do
        [ -f "$png" ] || continue
        cmp -s "$png" "$results/$name/$(basename "$png")" || fail "$name: $(basename "$png") differs from the local one"
    done
    merged=$((merged + 1))
done
declared="$("$gilab" experiment list | grep -c '^  [a-z0-9-]* \[')"
[ "$merged" -eq "$declared" ] || fail "$merged experiments compared, $declared declared (the local run $local_results lacks some)"
grep -q "total: .* done, 0 running, 0 pending, 0 failed" <<<"$("$gilab" sweep status "$results/.sweep")" ||
    fail "sweep status: not all done"
echo "PASS: all $merged declared experiments through Slurm give the local tables and images"
