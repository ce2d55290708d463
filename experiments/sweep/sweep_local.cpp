#include "experiments/sweep/sweep_local.hpp"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <functional>
#include <map>
#include <string>
#include <vector>
#include "core/util/error.hpp"
#include "core/util/format.hpp"
#include "core/util/parallel.hpp"

extern char** environ;

namespace gilab {

namespace fs = std::filesystem;

namespace {

// One process of the sweep: a task, or the rendering of a reference group's references.
struct SweepProcess {
    SweepTask task;
    std::vector<std::string> arguments;  // after `gilab [--assets A] --threads T`
    fs::path log;
    std::string label;
};

struct Running {
    const SweepProcess* process;
    std::chrono::steady_clock::time_point started;
};

// Starts `gilab [--assets A] --threads T ARGUMENTS…` with its output in the process's log.
pid_t start(const Sweep& sweep, const SweepProcess& process, int threads) {
    std::vector<std::string> args = {sweep.gilab.string()};
    if (!sweep.assets.empty()) args.insert(args.end(), {"--assets", sweep.assets});
    args.insert(args.end(), {"--threads", std::to_string(threads)});
    args.insert(args.end(), process.arguments.begin(), process.arguments.end());
    std::vector<char*> argv;
    for (std::string& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);

    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 1, process.log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_adddup2(&actions, 1, 2);
    pid_t pid = -1;
    const int status = posix_spawn(&pid, sweep.gilab.c_str(), &actions, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    if (status != 0)
        throw Error(sweep.gilab.string(), std::string("cannot start a task process: ") + std::strerror(status));
    return pid;
}

std::string describe_exit(int status) {
    if (WIFEXITED(status)) return "exit code " + std::to_string(WEXITSTATUS(status));
    if (WIFSIGNALED(status)) return std::string("killed by ") + sigabbrev_np(WTERMSIG(status));
    return "ended abnormally";
}

// Runs the processes, `jobs` at a time; `succeeded` judges one that exited 0. Returns the
// labels of those that failed.
std::vector<std::string> run_all(const Sweep& sweep, const std::vector<SweepProcess>& processes, int jobs, int threads,
                                 const std::function<bool(const SweepProcess&)>& succeeded, std::ostream& out) {
    std::map<pid_t, Running> running;
    size_t next = 0, finished = 0;
    std::vector<std::string> failed;
    while (next < processes.size() || !running.empty()) {
        while (next < processes.size() && int(running.size()) < jobs) {
            const SweepProcess& p = processes[next++];
            running[start(sweep, p, threads)] = {&p, std::chrono::steady_clock::now()};
        }
        int status = 0;
        const pid_t pid = waitpid(-1, &status, 0);
        if (pid < 0) {
            if (errno == EINTR) continue;
            throw Error("sweep", std::string("waiting for the task processes failed: ") + std::strerror(errno));
        }
        const auto it = running.find(pid);
        if (it == running.end()) continue;  // not one of ours
        const Running done = it->second;
        running.erase(it);
        ++finished;
        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - done.started).count();
        out << "[" << finished << "/" << processes.size() << "] " << done.process->label;
        if (WIFEXITED(status) && WEXITSTATUS(status) == 0 && succeeded(*done.process)) {
            char text[32];
            std::snprintf(text, sizeof text, "%.1f", seconds);
            out << " done (" << text << " s)" << std::endl;
        } else {
            out << " FAILED (" << describe_exit(status) << "); log: " << done.process->log.string() << std::endl;
            failed.push_back(done.process->label);
        }
    }
    return failed;
}

}  // namespace

int run_sweep_locally(const Sweep& sweep, const LocalSweepOptions& options, std::ostream& out, std::ostream& err) {
    const std::vector<SweepTask> all = sweep_tasks(sweep);
    const std::vector<SweepTask> pending = tasks_without_result(sweep);
    const int cores = default_thread_count();
    const int jobs = std::max(1, std::min<int>(options.jobs > 0 ? options.jobs : cores, int(pending.size())));
    const int threads = options.threads > 0 ? options.threads : std::max(1, cores / jobs);
    const fs::path logs = sweep.directory() / "logs";
    fs::create_directories(logs);
    out << "sweep: " << all.size() << " tasks of " << sweep.experiments.size() << " experiment(s); "
        << all.size() - pending.size() << " have a result already, " << pending.size() << " to run, " << jobs
        << " at a time with " << threads << " thread(s) each" << std::endl;

    std::vector<SweepProcess> references;
    for (const SweepTask& t : reference_tasks(sweep, pending)) {
        const std::string name = t.experiment + "." + std::to_string(t.id);
        references.push_back({t, references_arguments(sweep, t), logs / (name + ".references.log"),
                              t.experiment + " task " + std::to_string(t.id) + "'s references"});
    }
    if (!references.empty()) {
        // The cores shared among the reference processes alone: fewer groups than task
        // processes get more threads each.
        const int reference_jobs = std::min<int>(jobs, int(references.size()));
        const int reference_threads = options.threads > 0 ? options.threads : std::max(1, cores / reference_jobs);
        out << "references first: " << references.size() << " reference group(s) into "
            << (sweep.results_root / ".references").string() << ", " << reference_jobs << " at a time with "
            << reference_threads << " thread(s) each" << std::endl;
        const std::vector<std::string> failed = run_all(sweep, references, reference_jobs, reference_threads,
                                                        [](const SweepProcess&) { return true; }, out);
        if (!failed.empty())
            err << "gilab: sweep: rendering references failed for " << join(failed)
                << "; the tasks that need them try again themselves" << std::endl;
    }

    std::vector<SweepProcess> tasks;
    for (const SweepTask& t : pending)
        tasks.push_back({t, run_task_arguments(sweep, t), logs / (t.experiment + "." + std::to_string(t.id) + ".log"),
                         t.experiment + " task " + std::to_string(t.id)});
    // The result file, not the exit code alone, says whether a task is done.
    const std::vector<std::string> failed = run_all(
        sweep, tasks, jobs, threads, [&sweep](const SweepProcess& p) { return task_done(sweep, p.task); }, out);
    const int merge_failures = merge_sweep(sweep, out, err);
    if (!failed.empty())
        err << "gilab: sweep: " << failed.size() << " task(s) failed: " << join(failed)
            << "; their cells are missing from the tables. Run the same command again (or `gilab sweep resume "
            << sweep.directory().string() << "`) to run only the tasks without a result." << std::endl;
    return failed.empty() && merge_failures == 0 ? 0 : 1;
}

}  // namespace gilab
