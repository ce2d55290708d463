#!/usr/bin/env python3
"""Prints an experiment's tables (RESULTS/NAME/results.json) without the columns that
measure the run rather than the algorithm: times, rates, memory, thread counts and the
ratios between them. What is left is the same to the bit wherever and however the tasks
ran (locally, one process or many, on Slurm), which the sweep tests check.

    deterministic_tables.py RESULTS/NAME/results.json            the tables, as JSON
    deterministic_tables.py --columns RESULTS/NAME/results.json  the columns left out
"""
import json
import re
import sys

# What in a column's name marks a measurement of the run.
RUN_MEASURES = re.compile(
    r"(^|[^a-z])(ms|us)($|[^a-z])|\(s\)|fps|per_s|/s\)"  # times and rates: render_ms, ms to …, build (s)
    r"|rss|peak growth|\(×\)"                         # process memory, and ratios of it
    r"|threads"                                        # how the task ran
    r"|speedup|_over_|/kd|/nanoflann|/no-heap|/fused|/off|vs shadow map",  # ratios of times
    re.IGNORECASE)


def measures_the_run(column):
    return RUN_MEASURES.search(column) is not None


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
