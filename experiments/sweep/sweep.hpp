#pragma once
// A sweep: the tasks of several declared experiments (experiment_spec.hpp), run as
// separate `gilab experiment run-task` processes — here (sweep_local.hpp) or as a Slurm
// job array (sweep_slurm.hpp) — and merged into each experiment's tables afterwards.
// A task is done when its result file exists (run-task writes it atomically), so a sweep
// is resumed by running what has no result. The sweep's record, RESULTS/.sweep/sweep.json,
// lets `gilab sweep status | resume | merge DIR` pick it up later, on another machine too.
#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <ostream>
#include <string>
#include <vector>
#include <nlohmann/json.hpp>
#include "experiments/runner/experiment.hpp"
#include "experiments/runner/experiment_spec.hpp"

namespace gilab {

struct SweepTask {
    std::string experiment;
    int id = 0;  // in the experiment's plan
};

// An experiment of a sweep: the declared one along the sweep's extra axes, and its plan.
struct SweepExperiment {
    Experiment experiment;
    std::vector<SpecTask> plan;
};

struct Sweep {
    std::vector<std::string> experiments;  // declared experiments, in the order given
    std::vector<std::string> axes;         // extra axes for all of them, SETTING=V1,V2,… (with_extra_axes)
    bool quick = false;
    uint64_t seed = 1;
    std::filesystem::path results_root;    // absolute: the tasks may run elsewhere
    std::string assets;                    // --assets as given; "" = $GILAB_ASSETS where a task runs
    std::filesystem::path gilab;           // the program each task runs (absolute)
    std::string on = "local";              // local | slurm
    nlohmann::json slurm = nlohmann::json::object();        // the Slurm options (sweep_slurm.hpp)
    nlohmann::json submissions = nlohmann::json::array();   // one object per submitted round
    // experiment()'s, by name, quick or full, and axes; shared by copies of the sweep.
    mutable std::shared_ptr<std::map<std::string, SweepExperiment>> made = std::make_shared<std::map<std::string, SweepExperiment>>();

    std::filesystem::path directory() const { return results_root / ".sweep"; }
    // Experiment `name` of the sweep, made once (its spec checked with the axes).
    const SweepExperiment& experiment(const std::string& name) const;
    nlohmann::json to_json() const;
    static Sweep from_json(const nlohmann::json& j);
};

// The declared experiments named (`all`: every declared one), checked: an unknown name or
// one not declared as a spec is an Error naming it. Duplicates are dropped.
std::vector<std::string> sweep_experiment_names(const std::vector<std::string>& names);

// Every task of every experiment of the sweep, experiment by experiment in plan order.
std::vector<SweepTask> sweep_tasks(const Sweep& sweep);

// The task's result file, and whether it holds this task's result (one written for
// another plan — another seed, spec or axes — is not).
std::filesystem::path task_result_file(const Sweep& sweep, const SweepTask& task);
bool task_done(const Sweep& sweep, const SweepTask& task);
std::vector<SweepTask> tasks_without_result(const Sweep& sweep);

// The arguments after `gilab [--assets A]` that run the task:
// experiment run-task NAME ID [--quick] --seed S --results DIR.
std::vector<std::string> run_task_arguments(const Sweep& sweep, const SweepTask& task);

// Path-traced references (experiments/runner/path_reference.hpp) are rendered before the
// tasks, as tasks of their own: one per reference group (spec_runner.hpp) among `tasks`,
// the first task of each group standing for it. Their arguments are those of
// `gilab experiment references NAME ID …`, which renders the task's references into
// RESULTS/.references; a task whose references are there only reads them.
std::vector<SweepTask> reference_tasks(const Sweep& sweep, const std::vector<SweepTask>& tasks);
std::vector<std::string> references_arguments(const Sweep& sweep, const SweepTask& task);

// What the task cost by its result: its CPU time when it ran on one thread (other work on
// the machine does not inflate that, as it inflates wall time), else its wall time
// (`seconds`); nothing without a result.
std::optional<double> task_seconds(const Sweep& sweep, const SweepTask& task);
// The same for rendering the references of reference task `task` (reference_tasks), from
// the cost file `experiment references` writes; nothing when they were not rendered.
std::optional<double> references_seconds(const Sweep& sweep, const SweepTask& task);

// The wall time of tasks taking `seconds` each on `slots` machines that each run one task
// at a time, the longest tasks first, each to the machine free first (LPT list
// scheduling: within 4/3 of the best order). Never less than the longest task.
double wall_seconds_on(std::vector<double> seconds, int slots);

// Writes and reads DIR/sweep.json (atomically); reading names the file on a bad one.
void save_sweep(const Sweep& sweep);
Sweep load_sweep(const std::filesystem::path& sweep_dir);

// Merges each experiment's task files into its tables, as `gilab experiment merge` does,
// but into a staging copy (hard links) published in one rename, so RESULTS/NAME always
// holds a whole merge. Missing tasks are listed in the tables' notes. Returns the number
// of experiments that could not be merged (each said on `err`), then writes the report.
int merge_sweep(const Sweep& sweep, std::ostream& out, std::ostream& err);

}  // namespace gilab
