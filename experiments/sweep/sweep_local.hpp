#pragma once
// `gilab sweep --on local`: the sweep's tasks run here, each as its own
// `gilab experiment run-task` process (so a crash or a kill loses one task, never a
// result file), up to `jobs` at a time; tasks whose result file exists are skipped, so
// running the same command again resumes. The path-traced references the tasks share go
// first, one `gilab experiment references` process per reference group (sweep.hpp).
// Then each experiment is merged (merge_sweep).
#include <filesystem>
#include <ostream>
#include "experiments/sweep/sweep.hpp"

namespace gilab {

struct LocalSweepOptions {
    int jobs = 0;     // worker processes; 0 = the cores
    int threads = 0;  // threads per task; 0 = the cores shared out among the workers
};

// Returns the exit code: 0 when every task has a result and every experiment merged,
// 1 otherwise (the tasks that failed are named, with their logs under DIR/logs/).
int run_sweep_locally(const Sweep& sweep, const LocalSweepOptions& options, std::ostream& out, std::ostream& err);

}  // namespace gilab
