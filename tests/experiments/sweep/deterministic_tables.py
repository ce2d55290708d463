#!/usr/bin/env python3
"""Prints an experiment's tables (RESULTS/NAME/results.json) without the columns that
measure the run rather than the algorithm: times, rates, memory, thread counts and the
ratios between them (by unit, or by name for the ratios). What is left is the same to the
bit wherever and however the tasks ran (locally, one process or many, on Slurm), which
the sweep tests check; a new experiment's ratio of times must be named here.

    deterministic_tables.py RESULTS/NAME/results.json            the tables, as JSON
    deterministic_tables.py --columns RESULTS/NAME/results.json  the columns left out
"""
import json
import re
import sys

# Times, rates and process memory, by the unit in a column's name: render_ms, "ms to
# relMSE …", "build (s)", fps, mrays_per_s, "(10⁶/s)", peak RSS, peak growth.
RUN_UNITS = re.compile(
    r"(^|[^a-z])(ms|us)($|[^a-z])|\(s\)|fps|(^|_)per_s($|[^a-z])|/s\)|rss|peak growth", re.IGNORECASE)

# Ratios of such measurements, and how the run was made, by name.
RUN_RATIOS = {
    "threads", "speedup", "stream_over_single", "esvo_over_svo_throughput", "svdag_over_svo_throughput",
    "svdag_over_svo_time", "vs shadow map (%)", "mean vs shadow map (%)", "peak / frame SVO (×)",
    "peak growth / frame SVO (×)", "peak growth / (frame SVO + shared DAG) (×)", "hash/kd", "hash/nanoflann",
    "kd/nanoflann", "heap/no-heap", "split/fused", "cell_groups/off (both walking cells)",
    "paper/off (both walking tiles)", "right_over_left", "dense_over_cascaded", "cascaded_over_dense",
    "speedup_vs_paper_t_A (1 thread)", "speedup_vs_paper_t_A (all threads)",
    # vct-equal-time: the quality each technique reaches in a time budget, and its errors.
    "quality setting at equal time", "relMSE at equal time", "FLIP at equal time",
}


def measures_the_run(column):
    return column in RUN_RATIOS or RUN_UNITS.search(column) is not None


def main(argv):
    columns_only = argv[:1] == ["--columns"]
    path = argv[-1]
    tables = json.load(open(path))["tables"]
    if columns_only:
        left_out = sorted({c for t in tables for r in t["rows"] for c in r if measures_the_run(c)})
        print("\n".join(left_out))
        return 0
    for t in tables:
        t["columns"] = [c for c in t.get("columns", []) if not measures_the_run(c)]
        t["rows"] = [{k: v for k, v in r.items() if not measures_the_run(k)} for r in t["rows"]]
    print(json.dumps(tables, sort_keys=True, indent=1, ensure_ascii=False))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
