#!/usr/bin/env python3
"""Writes experiments/sweep/task_costs.json from the task results of sweeps: for each
experiment, the longest task of its quick and of its full plan in seconds (a task's
`cpu_seconds` when it ran on one thread, which other work on the machine does not inflate,
else its wall `seconds`), taken only where every task of the plan has a result. An
experiment or plan without all its results keeps the entry the current table has, so a
table can be filled over several runs.

    scripts/task_costs.py --gilab build/gilab --measured-on "MACHINE, 1 thread per task, DATE" RESULTS...
"""
import argparse
import glob
import json
import os
import subprocess
import sys

TABLE = os.path.join(os.path.dirname(__file__), "..", "experiments", "sweep", "task_costs.json")


def task_cost(result):
    if result.get("threads") == 1 and "cpu_seconds" in result:
        return result["cpu_seconds"]
    return result["seconds"]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--measured-on", required=True, help="the machine, threads per task and date")
    parser.add_argument("--gilab", required=True, help="the gilab program (for the plans' sizes)")
    parser.add_argument("results", nargs="+", help="results folders (RESULTS/NAME/tasks/{quick,full}/ID.json)")
    args = parser.parse_args()
    table = json.load(open(TABLE)) if os.path.exists(TABLE) else {"experiments": {}}
    for results in args.results:
        for plan, key in (("quick", "quick_longest_s"), ("full", "full_longest_s")):
            for name_dir in sorted(glob.glob(os.path.join(results, "*", "tasks", plan))):
                name = os.path.basename(os.path.dirname(os.path.dirname(name_dir)))
                seconds = [task_cost(json.load(open(f))) for f in glob.glob(os.path.join(name_dir, "*.json"))]
                tasks = subprocess.run([args.gilab, "experiment", "plan", name] + (["--quick"] if plan == "quick" else []),
                                       check=True, capture_output=True, text=True).stdout.splitlines()
                if seconds and len(seconds) == len(tasks):
                    table["experiments"].setdefault(name, {})[key] = round(max(seconds), 1)
    table["measured_on"] = args.measured_on
    table["experiments"] = dict(sorted(table["experiments"].items()))
    with open(TABLE, "w") as out:
        json.dump(table, out, indent=1, ensure_ascii=False)
        out.write("\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
