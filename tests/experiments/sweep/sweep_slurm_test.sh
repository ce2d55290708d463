#!/usr/bin/env bash
# `gilab sweep --on slurm` end to end on a real single-node Slurm (scripts/slurm_local.sh):
# two quick experiments as one job array after the array rendering their shared
# references, one task made to fail and one requeued (`scontrol requeue`, as on
# pre-emption) while it runs, the dependent merge job listing only the failed task as
# missing, `gilab sweep resume` submitting only it, and the merged tables then equal to a
# local sweep's (the columns that are not timings).
# Skipped (exit 77) only when the assets are missing or the daemons cannot start.
#   usage: sweep_slurm_test.sh GILAB SOURCE_DIR
set -euo pipefail
gilab="$1"
source_dir="$2"
experiments=(core-rays pm-radius-sweep)
failing=pm-radius-sweep/2
requeued=core-rays/1  # line 2 of the task list: array index 0 with --batch 2

source "$source_dir/tests/experiments/sweep/slurm_test_lib.sh"
require_assets bunny/stanford-bunny.obj sponza/sponza.obj conference/conference.obj
start_cluster

echo "== local sweep (the reference)"
"$gilab" sweep "${experiments[@]}" --quick --results "$work/local" --jobs 2 >"$work/local.out" 2>&1 ||
    { cat "$work/local.out"; fail "the local sweep failed"; }

echo "== slurm sweep, $failing failing, $requeued requeued while it runs"
out="$(GILAB_FAIL_TASK=$failing GILAB_TASK_DELAY=$requeued:6 "$gilab" sweep "${experiments[@]}" --quick --on slurm \
    --results "$work/slurm" --batch 2 2>&1)" || fail "gilab sweep --on slurm failed: $out"
echo "$out"
jobs="$(job_ids "$out")"
IFS=, read -r references_job array_job merge_job <<<"$jobs"
[ -n "$merge_job" ] || fail "no references job (pm-radius-sweep compares against a reference)"
log="$work/slurm/.sweep/logs/array.1_0.out"
for _ in $(seq 120); do grep -qs "before writing the result" "$log" && break; sleep 0.5; done
grep -qs "before writing the result" "$log" || fail "$requeued did not finish its work within 60 s"
scontrol requeue "${array_job}_0"
sleep 1
[ ! -f "$work/slurm/core-rays/tasks/quick/1.json" ] || fail "the requeued task left a result"
[ -z "$(find "$work/slurm/core-rays/tasks/quick" -name '.*')" ] || fail "the requeued task left a partial file"
# Slurm holds a requeued job back a while (its begin time); let it go now.
scontrol update jobid="${array_job}_0" StartTime=now
wait_for_jobs "$jobs"
grep -q "reference from the store" "$work/slurm/.sweep/logs/"array.1_*.out ||
    fail "no task found its reference in the store"
grep -q "rendering the path-traced reference" "$work/slurm/.sweep/logs/"array.1_*.out &&
    fail "a task rendered a reference the references job had rendered"
[ "$(json_field "$work/slurm/core-rays/results.json" config effective tasks_missing)" = "[]" ] ||
    fail "core-rays misses tasks after the requeued one ran again"
merged="$work/slurm/pm-radius-sweep/results.json"
[ -f "$merged" ] || { cat "$work/slurm/.sweep/logs/"*; fail "the merge job wrote no $merged"; }
missing="$(json_field "$merged" config effective tasks_missing)"
[ "$missing" = "[2]" ] || fail "the merge lists missing tasks $missing, not [2]"
[ ! -f "$work/slurm/pm-radius-sweep/tasks/quick/2.json" ] || fail "the failed task left a result"
grep -q "failed on purpose" "$work/slurm/.sweep/logs/"array.1_*.out || fail "no array log shows the failure"
status="$("$gilab" sweep status "$work/slurm/.sweep")"
echo "$status"
grep -q "pm-radius-sweep: 3 done, 1 failed (2)" <<<"$status" || fail "sweep status does not show task 2 failed"

echo "== resume"
out="$("$gilab" sweep resume "$work/slurm/.sweep" 2>&1)" || fail "gilab sweep resume failed: $out"
echo "$out"
grep -q "resuming: 1 task(s) without a result" <<<"$out" || fail "resume did not submit exactly the failed task"
[ "$(cat "$work/slurm/.sweep/tasks.2.txt" | cut -d' ' -f1-2)" = "pm-radius-sweep 2" ] || fail "round 2's task list is not task 2"
jobs="$(job_ids "$out")"
wait_for_jobs "$jobs"
[ "$(json_field "$merged" config effective tasks_missing)" = "[]" ] || fail "tasks still missing after resume"
grep -q "total: 7 done, 0 running, 0 pending, 0 failed" <<<"$("$gilab" sweep status "$work/slurm/.sweep")" ||
    fail "sweep status after resume: not all done"
for name in "${experiments[@]}"; do same_tables "$name" "$work/local" "$work/slurm"; done
[ -f "$work/slurm/report.html" ] || fail "the merge job wrote no report"
echo "PASS: the Slurm sweep, its failed task and its resume give the local tables"
