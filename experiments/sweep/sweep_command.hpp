#pragma once
// `gilab sweep`: the tasks of several declared experiments here or on a Slurm cluster.
//
//   gilab sweep NAMES...|all [--quick] [--axis SETTING=V1,V2,...] [--results DIR] [--seed N]
//               [--on local|slurm] ...
//   gilab sweep status DIR    tasks done / running / pending / failed
//   gilab sweep resume DIR    runs (or submits) only the tasks without a result
//   gilab sweep merge DIR     the tables and the report from the results there are
//
// DIR is the sweep's folder, RESULTS/.sweep.
#include <ostream>
#include <string>
#include <vector>
#include <CLI/CLI.hpp>
#include "experiments/sweep/sweep_local.hpp"
#include "experiments/sweep/sweep_slurm.hpp"

namespace gilab {

struct SweepCommand {
    std::vector<std::string> arguments;  // names, or status|resume|merge DIR
    bool quick = false;
    std::vector<std::string> axes;  // extra sweep axes, SETTING=V1,V2,…
    std::string results = "results";
    uint64_t seed = 1;
    std::string on = "local";
    LocalSweepOptions local;
    SlurmSweepOptions slurm;
    std::string assets;  // the global --assets
    int threads = 0;     // the global --threads (per task when given)
    std::string gilab;   // the program the tasks run; "" = this one
};

// Adds the `sweep` subcommand and its options, filling `command`.
CLI::App* add_sweep_subcommand(CLI::App& app, SweepCommand& command);

// Returns the exit code; bad input is thrown as Error.
int run_sweep_command(const SweepCommand& command, std::ostream& out, std::ostream& err);

}  // namespace gilab
