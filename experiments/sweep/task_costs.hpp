#pragma once
// How long an experiment's tasks take: the longest task of its quick and of its full plan,
// measured once on a known machine (experiments/sweep/task_costs.json, compiled in;
// scripts/task_costs.py writes it from a sweep's results). `gilab sweep --on slurm`
// derives its default time limit per task from it.
#include <optional>
#include <string>

namespace gilab {

// The longest task of the experiment's plan in seconds, or nothing when not measured.
std::optional<double> longest_task_seconds(const std::string& experiment, bool quick);

// Where the figures were measured: machine, threads per task, date.
std::string task_costs_measured_on();

}  // namespace gilab
