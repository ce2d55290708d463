#!/usr/bin/env bash
# `gilab sweep --on slurm` end to end on a real single-node Slurm (scripts/slurm_local.sh):
# two quick experiments as one job array with one task made to fail, the dependent merge
# job listing that task as missing, `gilab sweep resume` submitting only it, and the
# merged tables then equal to a local sweep's (the columns that are not timings).
# Skipped (exit 77) only when the assets are missing or the daemons cannot start.
#   usage: sweep_slurm_test.sh GILAB SOURCE_DIR
set -euo pipefail
gilab="$1"
source_dir="$2"
experiments=(core-rays pm-radius-sweep)
failing=pm-radius-sweep/2

for asset in bunny/stanford-bunny.obj sponza/sponza.obj conference/conference.obj; do
    found=""
    IFS=: read -r -a dirs <<<"${GILAB_ASSETS:-$source_dir/../shared/scenes}"
    for d in "${dirs[@]}"; do [ -f "$d/$asset" ] && found=1; done
    [ -n "$found" ] || { echo "SKIP: shared asset $asset not found (set GILAB_ASSETS)"; exit 77; }
done

work="$(mktemp -d /tmp/gilab-sweep-slurm.XXXXXX)"
cluster="$work/cluster"
finish() {
    status=$?
    "$source_dir/scripts/slurm_local.sh" stop "$cluster" >/dev/null 2>&1 || true
    if [ $status -eq 0 ] || [ $status -eq 77 ]; then rm -rf "$work"; else echo "kept for inspection: $work"; fi
    exit $status
}
trap finish EXIT

fail() { echo "FAIL: $*" >&2; exit 1; }

if ! start_output="$("$source_dir/scripts/slurm_local.sh" start "$cluster" 2>&1)"; then
    echo "$start_output"
    for log in "$cluster"/*.log; do [ -f "$log" ] && { echo "--- $log"; tail -n 5 "$log"; }; done
    echo "SKIP: the single-node Slurm could not start (above: why)"
    exit 77
fi
export SLURM_CONF="$cluster/slurm.conf"

# Waits until none of the jobs is queued or running (at most 150 s).
wait_for_jobs() {
    for _ in $(seq 300); do
        [ -z "$(squeue -h -j "$1" -t PD,R,CG,CF 2>/dev/null)" ] && return 0
        sleep 0.5
    done
    squeue -j "$1" || true
    fail "jobs $1 did not finish within 150 s"
}

# "submitted array job A (...) and merge job M" → A,M
job_ids() { sed -n 's/^submitted array job \([0-9]*\) .* merge job \([0-9]*\) .*/\1,\2/p' <<<"$1"; }

# The field at a JSON path of RESULTS/NAME/results.json, compact.
json_field() {
    python3 -c 'import json,sys; d=json.load(open(sys.argv[1])); [d:=d[k] for k in sys.argv[2:]]; print(json.dumps(d))' "$@"
}

# The tables of results.json without timing columns (they differ from run to run).
tables() {
    python3 - "$1" <<'PY'
import json, sys
timing = ("_ms", "per_s", "_over_", "seconds")
tables = json.load(open(sys.argv[1]))["tables"]
for t in tables:
    t["rows"] = [{k: v for k, v in r.items() if not any(p in k for p in timing)} for r in t["rows"]]
print(json.dumps(tables, sort_keys=True, indent=1))
PY
}

echo "== local sweep (the reference)"
"$gilab" sweep "${experiments[@]}" --quick --results "$work/local" --jobs 2 >"$work/local.out" 2>&1 ||
    { cat "$work/local.out"; fail "the local sweep failed"; }

echo "== slurm sweep, $failing failing"
out="$(GILAB_FAIL_TASK=$failing "$gilab" sweep "${experiments[@]}" --quick --on slurm --results "$work/slurm" --batch 2 2>&1)" ||
    fail "gilab sweep --on slurm failed: $out"
echo "$out"
jobs="$(job_ids "$out")"
[ -n "$jobs" ] || fail "no job ids in the output"
wait_for_jobs "$jobs"
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
for name in "${experiments[@]}"; do
    diff <(tables "$work/local/$name/results.json") <(tables "$work/slurm/$name/results.json") ||
        fail "$name: the tables from Slurm differ from the local sweep's"
done
[ -f "$work/slurm/report.html" ] || fail "the merge job wrote no report"
echo "PASS: the Slurm sweep, its failed task and its resume give the local tables"
