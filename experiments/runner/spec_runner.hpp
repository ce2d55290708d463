#pragma once
// The generic runner of declared experiments (experiment_spec.hpp): a task is prepared
// through prepare_technique, rendered `frames` times and measured; its raw result goes
// atomically to results/NAME/tasks/{full|quick}/ID.json on its own, so tasks can run anywhere (one
// by one, on several machines, as a job array) and be merged afterwards. Running the
// whole experiment is plan, every task, then merge.
#include <filesystem>
#include <optional>
#include <string>
#include <nlohmann/json.hpp>
#include "experiments/runner/experiment.hpp"
#include "experiments/runner/experiment_spec.hpp"

namespace gilab {

// results/NAME/tasks/{full|quick}/ID.json under the experiment's output directory: the
// quick and the full plan number their tasks each from 0.
std::filesystem::path spec_task_file(const std::filesystem::path& output_dir, int task_id, bool quick);
// results/NAME/tasks/{full|quick}/references/ID.json: what rendering task ID's references
// took (seconds, cpu_seconds, threads, references), written by `experiment references`.
std::filesystem::path spec_references_cost_file(const std::filesystem::path& output_dir, int task_id, bool quick);

// Runs task `task_id` of the plan (ctx.quick chooses the plan) and writes its result
// file; returns the result. Throws Error naming the task for an id outside the plan.
nlohmann::json run_spec_task(const ExperimentSpec& spec, int task_id, const ExperimentContext& ctx);

// The path-traced references task `task_id` compares against (its technique variants'
// relMSE, its probes' references), rendered into the results folder's store
// (path_reference.hpp) unless there already; returns how many. A sweep runs this before
// the tasks, once per reference group, so tasks that share references do not wait for
// each other or render them twice.
int render_task_references(const ExperimentSpec& spec, int task_id, const ExperimentContext& ctx);

// Tasks with the same group need the same references ("" = the task needs none): the
// technique variants' scene, size and samples, or NAME/ID for a probe's own references.
std::string reference_group(const ExperimentSpec& spec, const SpecTask& task, bool quick);

// Task `task`'s result in `file` for this plan (quick, seed, spec), or nothing when the
// file is missing, unreadable or written for another plan.
std::optional<nlohmann::json> read_task_result(const ExperimentSpec& spec, const SpecTask& task, bool quick,
                                               uint64_t seed, const std::filesystem::path& file);

// The task as the plan lists it (`gilab experiment plan`, gilab.experiment_plan): its
// JSON, with its reference group as "references" when it has one.
nlohmann::json plan_entry(const ExperimentSpec& spec, const SpecTask& task, bool quick);

// Reduces the task files in ctx.output_dir/tasks into the experiment's tables. Refuses
// a task file written for another plan (another --quick, --seed, spec or task order)
// naming the file; tasks not run yet are listed in a note and in the config's
// effective.tasks_missing (such a merge is not a finished run for --resume), and no task
// at all is an Error.
ExperimentOutput merge_spec_tasks(const ExperimentSpec& spec, const ExperimentContext& ctx);

// How long task `task` took when its result file under ctx.output_dir was written (the
// same plan), or nothing: the plan's cost estimate.
std::optional<double> last_task_seconds(const ExperimentSpec& spec, const SpecTask& task, const ExperimentContext& ctx);

// Plan, run every task, merge: what `gilab experiment NAME` does for a declared one.
ExperimentOutput run_spec(const ExperimentSpec& spec, const ExperimentContext& ctx);

}  // namespace gilab
