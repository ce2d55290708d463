#include "experiments/sweep/sweep_local.hpp"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <map>
#include <string>
#include <vector>
#include "core/util/error.hpp"
#include "core/util/parallel.hpp"

extern char** environ;

namespace gilab {

namespace fs = std::filesystem;

namespace {

struct RunningTask {
    SweepTask task;
    fs::path log;
    std::chrono::steady_clock::time_point started;
};

fs::path task_log(const Sweep& sweep, const SweepTask& task) {
    return sweep.directory() / "logs" / (task.experiment + "." + std::to_string(task.id) + ".log");
}

// Starts `gilab [--assets A] --threads T experiment run-task …` with its output in `log`.
pid_t start_task(const Sweep& sweep, const SweepTask& task, int threads, const fs::path& log) {
    std::vector<std::string> args = {sweep.gilab.string()};
    if (!sweep.assets.empty()) args.insert(args.end(), {"--assets", sweep.assets});
    args.insert(args.end(), {"--threads", std::to_string(threads)});
    for (std::string& a : run_task_arguments(sweep, task)) args.push_back(std::move(a));
    std::vector<char*> argv;
    for (std::string& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);

    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
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

}  // namespace

int run_sweep_locally(const Sweep& sweep, const LocalSweepOptions& options, std::ostream& out, std::ostream& err) {
    const std::vector<SweepTask> all = sweep_tasks(sweep);
    const std::vector<SweepTask> pending = tasks_without_result(sweep);
    const int cores = default_thread_count();
    const int jobs = std::max(1, std::min<int>(options.jobs > 0 ? options.jobs : cores, int(pending.size())));
    const int threads = options.threads > 0 ? options.threads : std::max(1, cores / jobs);
    fs::create_directories(sweep.directory() / "logs");
    out << "sweep: " << all.size() << " tasks of " << sweep.experiments.size() << " experiment(s); "
        << all.size() - pending.size() << " have a result already, " << pending.size() << " to run, " << jobs
        << " at a time with " << threads << " thread(s) each" << std::endl;

    std::map<pid_t, RunningTask> running;
    size_t next = 0, finished = 0;
    std::vector<std::string> failed;
    while (next < pending.size() || !running.empty()) {
        while (next < pending.size() && int(running.size()) < jobs) {
            const SweepTask& task = pending[next++];
            const fs::path log = task_log(sweep, task);
            running[start_task(sweep, task, threads, log)] = {task, log, std::chrono::steady_clock::now()};
        }
        int status = 0;
        const pid_t pid = waitpid(-1, &status, 0);
        if (pid < 0) {
            if (errno == EINTR) continue;
            throw Error("sweep", std::string("waiting for the task processes failed: ") + std::strerror(errno));
        }
        const auto it = running.find(pid);
        if (it == running.end()) continue;  // not one of ours
        const RunningTask done = it->second;
        running.erase(it);
        ++finished;
        const double seconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - done.started).count();
        const std::string label = done.task.experiment + " task " + std::to_string(done.task.id);
        out << "[" << finished << "/" << pending.size() << "] " << label;
        // The result file, not the exit code, says whether the task is done.
        if (WIFEXITED(status) && WEXITSTATUS(status) == 0 && task_done(sweep, done.task)) {
            char text[32];
            std::snprintf(text, sizeof text, "%.1f", seconds);
            out << " done (" << text << " s)" << std::endl;
        } else {
            out << " FAILED (" << describe_exit(status) << "); log: " << done.log.string() << std::endl;
            failed.push_back(label);
        }
    }
    const int merge_failures = merge_sweep(sweep, out, err);
    if (!failed.empty()) {
        std::string list;
        for (const std::string& f : failed) list += (list.empty() ? "" : ", ") + f;
        err << "gilab: sweep: " << failed.size() << " task(s) failed: " << list
            << "; their cells are missing from the tables. Run the same command again (or `gilab sweep resume "
            << sweep.directory().string() << "`) to run only the tasks without a result." << std::endl;
    }
    return failed.empty() && merge_failures == 0 ? 0 : 1;
}

}  // namespace gilab
