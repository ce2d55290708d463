#pragma once
// Runs several experiments in order so that an interrupted batch can be resumed.
//
// Each experiment writes into a hidden staging folder results/.NAME.partial and the
// finished folder replaces results/NAME in one rename, so results/NAME always holds one
// complete run (or nothing): a kill at any moment never leaves a half-written table.
// SIGINT and SIGTERM end the process at once (the work in flight is lost, the finished
// experiments are kept) after saying what was kept; the next batch removes leftover
// staging folders. With `resume`, an experiment whose results/NAME/results.json comes
// from a finished run of this build with the same quick flag, seed and thread count is
// skipped.
#include <filesystem>
#include <ostream>
#include <string>
#include <vector>
#include "experiments/runner/experiment.hpp"

namespace gilab {

struct ExperimentBatch {
    std::vector<const Experiment*> experiments;
    std::filesystem::path results_root = "results";
    bool quick = false;
    bool resume = false;
    uint64_t seed = 1;
    int threads = 0;  // 0 = all cores
    AssetPaths assets;
};

// Returns the exit code: 0, or 1 when an experiment failed (the others still run).
int run_experiment_batch(const ExperimentBatch& batch, std::ostream& out, std::ostream& err);

// Moves a finished staging folder to `final_dir` in one step, replacing an earlier one.
void publish_directory(const std::filesystem::path& staging, const std::filesystem::path& final_dir);

// The staging folder of one experiment's run in progress.
std::filesystem::path staging_directory(const std::filesystem::path& results_root, const std::string& name);

// Why results/NAME cannot be kept by --resume ("" when it can): no results.json, or one
// from another revision, quick flag, seed, thread count or (a declared one) spec.
std::string reason_to_rerun(const Experiment& experiment, const std::filesystem::path& experiment_dir, bool quick,
                            uint64_t seed, int threads);

}  // namespace gilab
