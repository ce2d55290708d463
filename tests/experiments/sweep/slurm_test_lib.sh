# Shared by the Slurm sweep tests (sourced): the asset check, a single-node Slurm started
# for the test in a temporary folder and stopped by its pid files on exit, and waiting
# for jobs. Sets `work` (the test's folder) and SLURM_CONF. Needs `source_dir` and
# `gilab` set and `set -euo pipefail`.

fail() { echo "FAIL: $*" >&2; exit 1; }

# Exit 77 (skipped) naming the first shared asset that is not installed.
require_assets() {
    local asset d found
    for asset in "$@"; do
        found=""
        IFS=: read -r -a dirs <<<"${GILAB_ASSETS:-$source_dir/../shared/scenes}"
        for d in "${dirs[@]}"; do [ -f "$d/$asset" ] && found=1; done
        [ -n "$found" ] || { echo "SKIP: shared asset $asset not found (set GILAB_ASSETS)"; exit 77; }
    done
}

finish() {
    status=$?
    "$source_dir/scripts/slurm_local.sh" stop "$work/cluster" >/dev/null 2>&1 || true
    if [ $status -eq 0 ] || [ $status -eq 77 ]; then rm -rf "$work"; else echo "kept for inspection: $work"; fi
    exit $status
}

# Starts the cluster in $work/cluster; exit 77 saying why when the daemons cannot start.
start_cluster() {
    work="$(mktemp -d /tmp/gilab-sweep-slurm.XXXXXX)"
    trap finish EXIT
    local start_output log
    if ! start_output="$("$source_dir/scripts/slurm_local.sh" start "$work/cluster" 2>&1)"; then
        echo "$start_output"
        for log in "$work/cluster"/*.log; do [ -f "$log" ] && { echo "--- $log"; tail -n 5 "$log"; }; done
        echo "SKIP: the single-node Slurm could not start (above: why)"
        exit 77
    fi
    export SLURM_CONF="$work/cluster/slurm.conf"
}

# Waits until none of the jobs (comma-separated ids) is queued or running, at most $2 s.
wait_for_jobs() {
    local limit="${2:-150}" i
    for ((i = 0; i < limit * 2; ++i)); do
        [ -z "$(squeue -h -j "$1" -t PD,R,CG,CF 2>/dev/null)" ] && return 0
        sleep 0.5
    done
    squeue -j "$1" || true
    fail "jobs $1 did not finish within $limit s"
}

# The job ids `gilab sweep --on slurm` printed: "REFERENCES,ARRAY,MERGE" (no REFERENCES
# when the round renders none).
job_ids() {
    local references array_and_merge
    references="$(sed -n 's/^submitted references job \([0-9]*\) .*/\1,/p' <<<"$1")"
    array_and_merge="$(sed -n 's/^submitted array job \([0-9]*\) .* merge job \([0-9]*\) .*/\1,\2/p' <<<"$1")"
    [ -n "$array_and_merge" ] || fail "no job ids in: $1"
    echo "$references$array_and_merge"
}

# The field at a JSON path of a results.json, compact.
json_field() {
    python3 -c 'import json,sys; d=json.load(open(sys.argv[1])); [d:=d[k] for k in sys.argv[2:]]; print(json.dumps(d))' "$@"
}

# Fails unless experiment NAME's tables under two results folders are equal apart from
# the columns that measure the run (deterministic_tables.py).
same_tables() {
    local name="$1" a="$2/$1/results.json" b="$3/$1/results.json"
    local tables="$source_dir/tests/experiments/sweep/deterministic_tables.py"
    [ -f "$a" ] || fail "$name: no $a"
    [ -f "$b" ] || fail "$name: no $b"
    diff <(python3 "$tables" "$a") <(python3 "$tables" "$b") || fail "$name: the tables of $2 and $3 differ (above)"
}
