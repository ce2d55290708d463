#pragma once
// `gilab experiment plan NAME`, `run-task NAME ID` and `merge NAME`: a declared
// experiment taken apart, so its tasks can run one by one, on other machines or as a job
// array, and be reduced afterwards into the same tables as the one-command run.
#include <filesystem>
#include <ostream>
#include <string>
#include <vector>
#include "core/io/asset_paths.hpp"

namespace gilab {

struct TaskCommand {
    std::string verb;                     // plan | run-task | references | merge
    std::vector<std::string> arguments;   // NAME [ID]
    std::filesystem::path results_root = "results";
    bool quick = false;
    uint64_t seed = 1;
    int threads = 0;
    AssetPaths assets;
    std::vector<std::string> axes;        // extra sweep axes, SETTING=V1,V2,… (with_extra_axes)
};

// The registered experiment `name` if it is declared as a spec; else an Error saying it
// runs only whole and naming the declared ones.
struct Experiment;
const Experiment& declared_experiment_named(const std::string& name);
// The same, swept along extra axes too (with_extra_axes); without any, the declared one.
Experiment declared_experiment_with_axes(const std::string& name, const std::vector<std::string>& axes);

// plan: one JSON line per task (id, scene, axes, variants with technique or probe and
// settings; seconds_last_run when RESULTS/NAME/tasks holds this task's result, as a
// cost estimate; `references`, the task's reference group, when it compares against
// path-traced references).
// run-task: runs task ID and writes RESULTS/NAME/tasks/{full|quick}/ID.json. For tests
// of failed and killed tasks: with $GILAB_FAIL_TASK=NAME/ID it fails instead, writing
// nothing; with $GILAB_TASK_DELAY=NAME/ID:SECONDS it waits that long after its work,
// before writing its result (spec_runner.cpp).
// references: renders the path-traced references task ID needs into RESULTS/.references
// (those there already are kept), so the tasks that need them find them.
// merge: writes RESULTS/NAME/results.csv, results.json and table.md from the tasks there.
// Returns the exit code; errors (an experiment that is not declared as a spec, a bad id)
// are thrown as Error.
int run_task_command(const TaskCommand& command, std::ostream& out);

}  // namespace gilab
