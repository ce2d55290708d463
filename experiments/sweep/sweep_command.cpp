#include "experiments/sweep/sweep_command.hpp"

#include <map>
#include "core/util/error.hpp"
#include "core/util/format.hpp"

namespace gilab {

namespace fs = std::filesystem;

CLI::App* add_sweep_subcommand(CLI::App& app, SweepCommand& c) {
    auto* sweep = app.add_subcommand(
        "sweep", "run the tasks of declared experiments in parallel here (--on local) or as a Slurm job array "
                 "(--on slurm), resumable, then merge them into each experiment's tables; also `status DIR`, "
                 "`resume DIR` and `merge DIR` for the sweep folder RESULTS/.sweep");
    sweep->add_option("names", c.arguments, "experiment names or `all`; or status|resume|merge DIR")->required();
    sweep->add_flag("--quick", c.quick, "the quick plans (small sizes)");
    sweep->add_option("--axis", c.axes,
                      "sweep every named experiment along one more axis, SETTING=V1,V2,... (repeatable); an axis of "
                      "the experiment on that setting takes these values instead. Use a --results of its own: the "
                      "tasks are numbered anew")
        ->allow_extra_args(false);
    sweep->add_option("--results", c.results, "results root directory (on a cluster: on the shared filesystem)")
        ->capture_default_str();
    sweep->add_option("--seed", c.seed, "random seed")->capture_default_str();
    sweep->add_option("--on", c.on, "where the tasks run")->check(CLI::IsMember({"local", "slurm"}))->capture_default_str();
    sweep->add_option("--jobs", c.local.jobs, "--on local: task processes at once (default: the cores)");
    sweep->add_option("--batch", c.slurm.batch, "--on slurm: tasks per array index (cheap tasks: fewer, longer indices)")
        ->capture_default_str();
    sweep->add_option("--partition", c.slurm.partition, "--on slurm: the partition (default: the cluster's)");
    sweep->add_option("--time", c.slurm.time, "--on slurm: time limit per task (MM, HH:MM:SS, D-HH:MM, ...)");
    sweep->add_option("--mem", c.slurm.mem, "--on slurm: memory per array index (sbatch --mem, e.g. 8G)");
    sweep->add_option("--throttle", c.slurm.throttle, "--on slurm: array indices running at once (--array ...%N)");
    sweep->add_option("--cpus-per-task", c.slurm.cpus_per_task, "--on slurm: cores per array index (the task's threads)")
        ->capture_default_str();
    sweep->add_option("--sbatch-arg", c.slurm.sbatch_args, "--on slurm: an extra sbatch flag, e.g. --account=X (repeatable)");
    sweep->add_flag("--dry-run", c.slurm.dry_run, "--on slurm: write the task list and job scripts, submit nothing");
    return sweep;
}

namespace {

fs::path this_program() {
    std::error_code ec;
    const fs::path self = fs::read_symlink("/proc/self/exe", ec);
    if (ec) throw Error("/proc/self/exe", "cannot find this program's path: " + ec.message());
    return self;
}

void require_no_slurm_options(const SweepCommand& c) {
    if (c.slurm.to_json() != SlurmSweepOptions().to_json() || c.slurm.dry_run)
        throw Error("sweep", "--batch, --partition, --time, --mem, --throttle, --cpus-per-task, --sbatch-arg and "
                             "--dry-run go with --on slurm only");
}

// status, resume and merge work on a sweep as it was started: its record holds the
// experiments, sizes, seed, results and Slurm options.
void require_no_sweep_options(const SweepCommand& c) {
    const SweepCommand defaults;
    SlurmSweepOptions slurm = c.slurm;
    slurm.dry_run = false;
    if (c.quick != defaults.quick || c.results != defaults.results || c.seed != defaults.seed || c.on != defaults.on ||
        !c.axes.empty() || slurm.to_json() != defaults.slurm.to_json())
        throw Error("sweep " + c.arguments[0], "takes the sweep's own options from its sweep.json; give only the folder "
                                               "(and --jobs or --dry-run for resume)");
}

fs::path sweep_folder(const SweepCommand& c) {
    if (c.arguments.size() != 2)
        throw Error("sweep " + c.arguments[0], "needs one folder: gilab sweep " + c.arguments[0] + " RESULTS/.sweep");
    return c.arguments[1];
}

std::string duration(double seconds) {
    char text[64];
    if (seconds < 120) std::snprintf(text, sizeof text, "%.1f s", seconds);
    else if (seconds < 7200) std::snprintf(text, sizeof text, "%.1f min", seconds / 60);
    else std::snprintf(text, sizeof text, "%.2f h", seconds / 3600);
    return text;
}

// The times the results hold (CPU time of one-thread tasks, else wall time): the tasks'
// sum and longest, the references' sum, and the wall time on 1, 4 and 16 machines running
// one process each at a time — the references first, then the tasks, as sweeps run them.
void print_measured_times(const Sweep& sweep, std::ostream& out) {
    std::vector<double> seconds, reference_seconds;
    double longest = 0;
    std::string longest_task;
    const std::vector<SweepTask> all = sweep_tasks(sweep);
    for (const SweepTask& t : all) {
        const std::optional<double> s = task_seconds(sweep, t);
        if (!s) continue;
        seconds.push_back(*s);
        if (*s > longest) {
            longest = *s;
            longest_task = t.experiment + " task " + std::to_string(t.id);
        }
    }
    for (const SweepTask& t : reference_tasks(sweep, all))
        if (const std::optional<double> s = references_seconds(sweep, t)) reference_seconds.push_back(*s);
    if (seconds.empty()) return;
    const auto sum = [](const std::vector<double>& v) {
        double total = 0;
        for (double s : v) total += s;
        return total;
    };
    out << "task time of the " << seconds.size() << " results (CPU time of one-thread tasks, else wall time): "
        << duration(sum(seconds)) << " in all, longest " << duration(longest) << " (" << longest_task << "); "
        << reference_seconds.size() << " reference group(s) rendered: " << duration(sum(reference_seconds))
        << "; one process at a time per machine, references first, longest first: ";
    for (int machines : {1, 4, 16}) {
        const double wall = (reference_seconds.empty() ? 0.0 : wall_seconds_on(reference_seconds, machines)) +
                            wall_seconds_on(seconds, machines);
        out << machines << (machines == 1 ? " machine " : " machines ") << duration(wall) << (machines == 16 ? "" : ", ");
    }
    out << std::endl;
}

int show_status(const Sweep& sweep, std::ostream& out) {
    SlurmTaskStates slurm;
    if (sweep.on == "slurm") slurm = query_slurm_states(sweep);
    std::map<std::string, int> totals;
    out << "sweep " << sweep.directory().string() << " (" << (sweep.quick ? "quick" : "full") << " plans, on "
        << sweep.on << ")" << std::endl;
    for (const std::string& name : sweep.experiments) {
        std::map<std::string, std::vector<int>> by_state;
        for (const SweepTask& t : sweep_tasks(sweep)) {
            if (t.experiment != name) continue;
            std::string state = "done";
            if (!task_done(sweep, t)) {
                const auto it = slurm.task_state.find(task_key(t));
                state = it != slurm.task_state.end() ? it->second : "without result";
            }
            by_state[state].push_back(t.id);
        }
        out << "  " << name << ":";
        bool first = true;
        for (const auto& [state, ids] : by_state) {
            out << (first ? " " : ", ") << ids.size() << " " << state;
            if (state != "done") {
                std::string list;
                for (int id : ids) {
                    if (!list.empty()) list += ' ';
                    list += std::to_string(id);
                }
                out << " (" << list << ")";
            }
            totals[state] += int(ids.size());
            first = false;
        }
        out << std::endl;
    }
    print_measured_times(sweep, out);
    out << "total: " << totals["done"] << " done, " << totals["running"] << " running, " << totals["pending"]
        << " pending, " << totals["failed"] << " failed";
    if (totals["without result"]) out << ", " << totals["without result"] << " without result (failed or not run)";
    out << std::endl;
    if (sweep.on == "slurm") {
        if (!slurm.queued_jobs.empty()) {
            const std::string jobs = join(slurm.queued_jobs, ",");
            out << "queued or running: jobs " << jobs << " (squeue -j " << jobs << ")" << std::endl;
        }
        if (!slurm.squeue_available) out << "squeue is not available here: Slurm's view of the tasks is not shown" << std::endl;
        else if (!slurm.sacct_available) out << "sacct is not available (accounting off): failures are inferred from "
                                                "tasks that left the queue without a result" << std::endl;
    }
    return 0;
}

int resume(Sweep sweep, const SweepCommand& c, std::ostream& out, std::ostream& err) {
    if (sweep.on == "local") {
        LocalSweepOptions local = c.local;
        local.threads = c.threads;  // `gilab --threads T sweep resume DIR`: T threads per task, as when started
        return run_sweep_locally(sweep, local, out, err);
    }
    const std::vector<SweepTask> pending = tasks_without_result(sweep);
    if (pending.empty()) {
        out << "every task has a result; merging here" << std::endl;
        return merge_sweep(sweep, out, err) == 0 ? 0 : 1;
    }
    const SlurmTaskStates states = query_slurm_states(sweep);
    if (!states.queued_jobs.empty()) {
        const std::string jobs = join(states.queued_jobs, ",");
        throw Error("sweep resume", "jobs " + jobs + " of this sweep are still queued or running; resuming now would "
                                    "run their tasks twice. Wait for them (squeue -j " + jobs +
                                    ") or cancel them (scancel " + jobs + ") first");
    }
    SlurmSweepOptions options = SlurmSweepOptions::from_json(sweep.slurm);
    options.dry_run = c.slurm.dry_run;
    out << "resuming: " << pending.size() << " task(s) without a result" << std::endl;
    submit_sweep_round(sweep, pending, options, out);
    return 0;
}

}  // namespace

int run_sweep_command(const SweepCommand& c, std::ostream& out, std::ostream& err) {
    const std::string& verb = c.arguments.at(0);
    if (verb == "status" || verb == "resume" || verb == "merge") {
        require_no_sweep_options(c);
        const Sweep sweep = load_sweep(sweep_folder(c));
        if (verb == "status") return show_status(sweep, out);
        if (verb == "merge") return merge_sweep(sweep, out, err) == 0 ? 0 : 1;
        return resume(sweep, c, out, err);
    }
    Sweep sweep;
    sweep.experiments = sweep_experiment_names(c.arguments);
    sweep.axes = c.axes;
    sweep.quick = c.quick;
    for (const std::string& name : sweep.experiments) sweep.experiment(name);  // the axes apply to each: checked now
    sweep.seed = c.seed;
    sweep.results_root = fs::absolute(c.results).lexically_normal();
    if (!sweep.results_root.has_filename()) sweep.results_root = sweep.results_root.parent_path();
    sweep.assets = c.assets;
    sweep.gilab = c.gilab.empty() ? this_program() : fs::path(c.gilab);
    sweep.on = c.on;
    if (c.local.jobs < 0) throw Error("--jobs", "must be at least 1 (or left out: the cores)");
    if (c.on == "local") {
        require_no_slurm_options(c);
        save_sweep(sweep);
        LocalSweepOptions local = c.local;
        local.threads = c.threads;
        return run_sweep_locally(sweep, local, out, err);
    }
    if (c.local.jobs != 0) throw Error("--jobs", "goes with --on local; with --on slurm, --throttle limits the indices at once");
    c.slurm.check();
    const std::vector<SweepTask> pending = tasks_without_result(sweep);
    const size_t all = sweep_tasks(sweep).size();
    out << "sweep: " << all << " tasks of " << sweep.experiments.size() << " experiment(s); " << all - pending.size()
        << " have a result already" << std::endl;
    if (pending.empty()) {
        out << "every task has a result; merging here" << std::endl;
        save_sweep(sweep);
        return merge_sweep(sweep, out, err) == 0 ? 0 : 1;
    }
    submit_sweep_round(sweep, pending, c.slurm, out);
    return 0;
}

}  // namespace gilab
