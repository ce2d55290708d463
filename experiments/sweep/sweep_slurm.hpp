#pragma once
// `gilab sweep --on slurm`: the sweep as one Slurm job array and one merge job.
//
// Each submission ("round") writes into the sweep's folder
//   tasks.R.txt     one line per task: the arguments of `gilab experiment run-task`
//                   (NAME ID [--quick] --seed S --results DIR); array index i runs lines
//                   i*K+1 … i*K+K (K = --batch, 1 by default: one task per index)
//   array.R.sbatch  the job array, one index per batch of K tasks; an index whose task
//                   fails exits non-zero (Slurm records it failed), its other tasks still run
//   merge.R.sbatch  `gilab sweep merge DIR` (tables and report), submitted with
//                   --dependency=afterany on the array so it runs however the tasks end
//   references.R.txt, references.R.sbatch
//                   when tasks compare against path-traced references: a job array
//                   before the tasks' (which depends on it, afterany) rendering each
//                   reference group's references once into RESULTS/.references
// and submits both with `sbatch --parsable`. Scheduling, retries (`scontrol requeue`),
// dependencies and accounting are Slurm's: gilab writes files and reads squeue/sacct.
#include <filesystem>
#include <map>
#include <ostream>
#include <string>
#include <vector>
#include <nlohmann/json.hpp>
#include "experiments/sweep/sweep.hpp"

namespace gilab {

struct SlurmSweepOptions {
    std::string partition;                 // "" = the cluster's default
    std::string time;                      // per task, in Slurm's format (MM, HH:MM:SS, D-HH:MM, ...)
    std::string mem;                       // per array index, as sbatch --mem takes it (4G)
    int throttle = 0;                      // at most this many indices at once (--array …%N); 0 = no limit
    int batch = 1;                         // tasks per array index
    int cpus_per_task = 1;                 // cores per index; each task runs with this many threads
    std::vector<std::string> sbatch_args;  // extra sbatch flags, for both jobs
    bool dry_run = false;                  // write the files, submit nothing

    nlohmann::json to_json() const;
    static SlurmSweepOptions from_json(const nlohmann::json& j);
    // Throws Error naming a bad option (batch or cpus below 1, a time sbatch would not take).
    void check() const;
};

// A Slurm time (MM, MM:SS, HH:MM:SS, D-HH, D-HH:MM, D-HH:MM:SS) in minutes, rounded up;
// Error naming the text when it is none of these.
long slurm_time_minutes(const std::string& text);

// The files' contents, for round `round` of `tasks`: the job array of the tasks, or the
// one before it that renders the reference groups' references (sweep.hpp).
enum class ArrayKind { Tasks, References };
std::string task_list_text(const Sweep& sweep, const std::vector<SweepTask>& tasks);
std::string array_script(const Sweep& sweep, const SlurmSweepOptions& options, size_t task_count, int round,
                         ArrayKind kind = ArrayKind::Tasks);
std::string merge_script(const Sweep& sweep, const SlurmSweepOptions& options, int round);

// The time limit per task when --time is not given, in minutes: 3 × the longest task
// measured for the experiments of `tasks` (task_costs.hpp), at least 10; "" when one of
// them has no measurement or the sweep has extra axes. `why` says which and why.
std::string default_time_limit(const Sweep& sweep, const std::vector<SweepTask>& tasks, std::string& why);

// Writes round R's files (R = submissions so far + 1) for `tasks` and, unless dry_run,
// submits them; records the round in `sweep` and saves sweep.json. Prints the job ids
// and how to watch them. Error when sbatch is missing or refuses (with its message).
void submit_sweep_round(Sweep& sweep, const std::vector<SweepTask>& tasks, const SlurmSweepOptions& options,
                        std::ostream& out);

// What Slurm says of the sweep's tasks: for each task (by task_key) in the latest round
// that holds it, "running", "pending" or "failed" (its index ended without the task's
// result, as squeue or sacct tell), or nothing when Slurm does not know (no squeue; the
// job has left the controller's memory and sacct is off).
struct SlurmTaskStates {
    bool squeue_available = false;
    bool sacct_available = false;
    std::vector<std::string> queued_jobs;          // the sweep's jobs squeue still lists
    std::map<std::string, std::string> task_state;  // task_key → running | pending | failed
};
std::string task_key(const SweepTask& task);  // "NAME ID"
SlurmTaskStates query_slurm_states(const Sweep& sweep);

}  // namespace gilab
