#include "experiments/sweep/sweep_slurm.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <set>
#include <sstream>
#include "core/image/image_io.hpp"
#include "core/util/error.hpp"
#include "core/util/format.hpp"
#include "experiments/sweep/program_call.hpp"
#include "experiments/sweep/task_costs.hpp"

namespace gilab {

namespace fs = std::filesystem;

nlohmann::json SlurmSweepOptions::to_json() const {
    return {{"partition", partition}, {"time", time},   {"mem", mem},
            {"throttle", throttle},   {"batch", batch}, {"cpus_per_task", cpus_per_task},
            {"sbatch_args", sbatch_args}};
}

SlurmSweepOptions SlurmSweepOptions::from_json(const nlohmann::json& j) {
    SlurmSweepOptions o;
    o.partition = j.value("partition", std::string());
    o.time = j.value("time", std::string());
    o.mem = j.value("mem", std::string());
    o.throttle = j.value("throttle", 0);
    o.batch = j.value("batch", 1);
    o.cpus_per_task = j.value("cpus_per_task", 1);
    o.sbatch_args = j.value("sbatch_args", std::vector<std::string>());
    return o;
}

namespace {

// Text that goes into a job script as one word: no blanks, quotes or line breaks.
void require_one_word(const std::string& text, const std::string& what) {
    for (unsigned char c : text)
        if (std::isspace(c) || c == '\'' || c == '"' || c == '\\')
            throw Error(what, "'" + text + "' holds a blank, quote or backslash; the job scripts need it as one word");
}

std::string quoted(const std::string& text) { return "'" + text + "'"; }

fs::path list_file(const Sweep& sweep, int round, ArrayKind kind) {
    return sweep.directory() / ((kind == ArrayKind::References ? "references." : "tasks.") + std::to_string(round) + ".txt");
}

std::string gilab_call(const Sweep& sweep) {
    std::string call = quoted(sweep.gilab.string());
    if (!sweep.assets.empty()) call += " --assets " + quoted(sweep.assets);
    return call;
}

void common_directives(std::ostringstream& s, const SlurmSweepOptions& o) {
    if (!o.partition.empty()) s << "#SBATCH --partition=" << o.partition << "\n";
    for (const std::string& a : o.sbatch_args) s << "#SBATCH " << a << "\n";
}

// sbatch --parsable prints "JOBID" or "JOBID;CLUSTER".
std::string submit(const std::vector<std::string>& args) {
    const ProgramResult r = call_program(args);
    std::string id = r.output.substr(0, r.output.find_first_of(";\n"));
    const bool numeric = !id.empty() && id.find_first_not_of("0123456789") == std::string::npos;
    if (r.exit_code != 0 || !numeric) {
        const std::string command = join(args, " ");
        throw Error("sbatch", "`" + command + "` failed (exit code " + std::to_string(r.exit_code) + "): " + r.output);
    }
    return id;
}

}  // namespace

long slurm_time_minutes(const std::string& text) {
    const auto bad = [&text]() {
        return Error("--time", "'" + text + "' is not a Slurm time (MM, MM:SS, HH:MM:SS, D-HH, D-HH:MM or D-HH:MM:SS)");
    };
    if (text.empty()) throw bad();
    long days = 0;
    std::string rest = text;
    const size_t dash = text.find('-');
    std::vector<long> parts;
    auto number = [&bad](const std::string& s) {
        if (s.empty() || s.size() > 6 || s.find_first_not_of("0123456789") != std::string::npos) throw bad();
        return std::stol(s);
    };
    if (dash != std::string::npos) {
        days = number(text.substr(0, dash));
        rest = text.substr(dash + 1);
    }
    std::stringstream fields(rest);
    for (std::string f; std::getline(fields, f, ':');) parts.push_back(number(f));
    if (parts.empty() || parts.size() > 3 || (!rest.empty() && rest.back() == ':')) throw bad();
    long seconds = 0;
    if (dash != std::string::npos) {  // D-HH[:MM[:SS]]
        const long units[] = {3600, 60, 1};
        for (size_t i = 0; i < parts.size(); ++i) seconds += parts[i] * units[i];
        seconds += days * 86400;
    } else if (parts.size() == 1) {  // MM
        seconds = parts[0] * 60;
    } else if (parts.size() == 2) {  // MM:SS
        seconds = parts[0] * 60 + parts[1];
    } else {  // HH:MM:SS
        seconds = parts[0] * 3600 + parts[1] * 60 + parts[2];
    }
    if (seconds <= 0) throw Error("--time", "'" + text + "' is no time at all; give the longest a task may take");
    return (seconds + 59) / 60;
}

void SlurmSweepOptions::check() const {
    if (batch < 1) throw Error("--batch", "must be at least 1 (tasks per array index)");
    if (cpus_per_task < 1) throw Error("--cpus-per-task", "must be at least 1");
    if (throttle < 0) throw Error("--throttle", "must be at least 1 (array indices running at once), or 0 for no limit");
    if (!time.empty()) slurm_time_minutes(time);
    require_one_word(partition, "--partition");
    require_one_word(mem, "--mem");
    for (const std::string& a : sbatch_args) {
        if (a.find('\n') != std::string::npos || a.rfind("-", 0) != 0)
            throw Error("--sbatch-arg", "'" + a + "' is not an sbatch flag (one line, starting with -)");
    }
}

std::string task_key(const SweepTask& task) { return task.experiment + " " + std::to_string(task.id); }

std::string task_list_text(const Sweep& sweep, const std::vector<SweepTask>& tasks) {
    std::string text;
    for (const SweepTask& t : tasks) {
        const std::vector<std::string> args = run_task_arguments(sweep, t);  // the same as `references` takes
        for (size_t i = 2; i < args.size(); ++i) text += args[i] + (i + 1 < args.size() ? " " : "\n");
    }
    return text;
}

std::string array_script(const Sweep& sweep, const SlurmSweepOptions& o, size_t task_count, int round, ArrayKind kind) {
    const bool references = kind == ArrayKind::References;
    // Reference groups are few and each a long render: one per index, so that they spread
    // over the nodes (--batch is for many cheap tasks).
    const int batch = references ? 1 : o.batch;
    const size_t indices = (task_count + size_t(batch) - 1) / size_t(batch);
    const std::string r = std::to_string(round);
    const std::string verb = references ? "references" : "run-task";
    std::ostringstream s;
    s << "#!/bin/bash\n"
      << "# gilab sweep, round " << r << ": " << task_count << (references ? " reference group(s)" : " task(s)") << " in "
      << indices << " array index(es). Index i\n"
      << "# runs lines i*" << batch << "+1 to i*" << batch << "+" << batch
      << " of the list, each as `gilab experiment " << verb << "`, which\n"
      << (references ? "# renders the task's path-traced references into the store, each whole or not at all.\n"
                     : "# writes its result file whole or not at all.\n")
      << "#SBATCH --job-name=gilab-sweep" << (references ? "-references" : "") << "\n"
      << "#SBATCH --array=0-" << indices - 1 << (o.throttle > 0 ? "%" + std::to_string(o.throttle) : "") << "\n"
      << "#SBATCH --output=" << (sweep.directory() / "logs").string() << "/" << (references ? "references." : "array.")
      << r << "_%a.out\n"
      << "#SBATCH --cpus-per-task=" << o.cpus_per_task << "\n";
    if (!o.time.empty()) s << "#SBATCH --time=" << slurm_time_minutes(o.time) * batch << "\n";
    if (!o.mem.empty()) s << "#SBATCH --mem=" << o.mem << "\n";
    common_directives(s, o);
    s << "set -u\n"
      << "tasks=" << quoted(list_file(sweep, round, kind).string()) << "\n"
      << "first=$(( SLURM_ARRAY_TASK_ID * " << batch << " + 1 ))\n"
      << "last=$(( first + " << batch - 1 << " ))\n"
      << "failed=0\n"
      << "while read -r -a task; do\n"
      << "    echo \"gilab sweep: experiment " << verb << " ${task[*]}\"\n"
      << "    " << gilab_call(sweep) << " --threads " << o.cpus_per_task << " experiment " << verb
      << " \"${task[@]}\" </dev/null || failed=1\n"
      << "done < <(sed -n \"${first},${last}p\" \"$tasks\")\n"
      << "exit $failed\n";
    return s.str();
}

std::string merge_script(const Sweep& sweep, const SlurmSweepOptions& o, int round) {
    std::ostringstream s;
    s << "#!/bin/bash\n"
      << "# gilab sweep, round " << round << ": the tables and the report from the task results there are\n"
      << "# (submitted to run after the array however its tasks ended).\n"
      << "#SBATCH --job-name=gilab-sweep-merge\n"
      << "#SBATCH --output=" << (sweep.directory() / "logs").string() << "/merge." << round << ".out\n";
    common_directives(s, o);
    s << "exec " << gilab_call(sweep) << " sweep merge " << quoted(sweep.directory().string()) << "\n";
    return s.str();
}

std::string default_time_limit(const Sweep& sweep, const std::vector<SweepTask>& tasks, std::string& why) {
    double longest = 0;
    std::set<std::string> unmeasured;
    for (const SweepTask& t : tasks) {
        if (const std::optional<double> s = longest_task_seconds(t.experiment, sweep.quick)) longest = std::max(longest, *s);
        else unmeasured.insert(t.experiment);
    }
    if (!unmeasured.empty() || !sweep.axes.empty()) {
        const std::string names = join(unmeasured);
        why = !sweep.axes.empty() ? "no --time: extra axes change the tasks' cost, so the cluster's default limit applies"
                                  : "no --time: the cluster's default limit applies (no measured task time for " + names +
                                        " in experiments/sweep/task_costs.json)";
        return "";
    }
    const long minutes = std::max(10L, long(std::ceil(3.0 * longest / 60.0)));
    why = "time limit per task: " + std::to_string(minutes) + " min, 3 × the longest task measured for these experiments (" +
          task_costs_measured_on() + "; --time overrides)";
    return std::to_string(minutes);
}

void submit_sweep_round(Sweep& sweep, const std::vector<SweepTask>& tasks, const SlurmSweepOptions& given,
                        std::ostream& out) {
    given.check();
    require_one_word(sweep.results_root.string(), "--results");
    require_one_word(sweep.gilab.string(), "the gilab program's path");
    require_one_word(sweep.assets, "--assets");
    for (const std::string& axis : sweep.axes) require_one_word(axis, "--axis");
    // The tasks' default limit comes from measured task times; the references' renders
    // are not measured there, so their array keeps the limit given (or the cluster's).
    SlurmSweepOptions options = given;
    if (options.time.empty() && !tasks.empty()) {
        std::string why;
        options.time = default_time_limit(sweep, tasks, why);
        out << why << std::endl;
    }
    if (tasks.empty()) throw Error("sweep", "no task to submit");
    if (!options.dry_run && !program_on_path("sbatch"))
        throw Error("sbatch", "not found on PATH, so this machine cannot submit Slurm jobs. On a cluster, run "
                              "`gilab sweep` on a login node (where sbatch is); on Debian, `apt-get install "
                              "slurm-wlm munge` gives the Slurm programs. Or run here with `--on local`, or write "
                              "the job files without submitting with `--dry-run`.");
    const int round = int(sweep.submissions.size()) + 1;
    const std::string r = std::to_string(round);
    fs::create_directories(sweep.directory() / "logs");
    const std::vector<SweepTask> references = reference_tasks(sweep, tasks);
    const fs::path references_file = sweep.directory() / ("references." + r + ".sbatch");
    const fs::path array_file = sweep.directory() / ("array." + r + ".sbatch");
    const fs::path merge_file = sweep.directory() / ("merge." + r + ".sbatch");
    if (!references.empty()) {
        write_file_atomically(list_file(sweep, round, ArrayKind::References), task_list_text(sweep, references));
        write_file_atomically(references_file,
                              array_script(sweep, given, references.size(), round, ArrayKind::References));
    }
    write_file_atomically(list_file(sweep, round, ArrayKind::Tasks), task_list_text(sweep, tasks));
    write_file_atomically(array_file, array_script(sweep, options, tasks.size(), round, ArrayKind::Tasks));
    write_file_atomically(merge_file, merge_script(sweep, options, round));
    nlohmann::json record = {{"round", round},
                             {"tasks_file", list_file(sweep, round, ArrayKind::Tasks).string()},
                             {"tasks", tasks.size()},
                             {"reference_groups", references.size()},
                             {"batch", options.batch},
                             {"references_job", ""},
                             {"array_job", ""},
                             {"merge_job", ""}};
    sweep.slurm = given.to_json();  // a resumed round takes its default time limit anew
    out << "wrote " << list_file(sweep, round, ArrayKind::Tasks).string() << " (" << tasks.size() << " tasks), "
        << array_file.string() << " and " << merge_file.string();
    if (!references.empty())
        out << ", and " << references_file.string() << " (" << references.size()
            << " reference group(s), rendered before the tasks)";
    out << std::endl;
    if (options.dry_run) {
        sweep.submissions.push_back(record);
        save_sweep(sweep);
        out << "dry run: nothing submitted; submit with\n";
        if (!references.empty())
            out << "  sbatch --parsable " << references_file.string() << "\n  sbatch --parsable --dependency=afterany:REFJOB "
                << array_file.string() << "\n";
        else
            out << "  sbatch --parsable " << array_file.string() << "\n";
        out << "  sbatch --dependency=afterany:JOBID " << merge_file.string() << std::endl;
        return;
    }
    // Each job is recorded as soon as it is in Slurm's hands, before anything else can fail.
    std::vector<std::string> array_args = {"sbatch", "--parsable"};
    if (!references.empty()) {
        record["references_job"] = submit({"sbatch", "--parsable", references_file.string()});
        // afterany: a reference that could not be rendered is rendered by its tasks.
        array_args.push_back("--dependency=afterany:" + record["references_job"].get<std::string>());
    }
    sweep.submissions.push_back(record);
    save_sweep(sweep);
    array_args.push_back(array_file.string());
    const std::string array_job = submit(array_args);
    sweep.submissions.back()["array_job"] = array_job;
    save_sweep(sweep);
    const std::string merge_job =
        submit({"sbatch", "--parsable", "--dependency=afterany:" + array_job, merge_file.string()});
    sweep.submissions.back()["merge_job"] = merge_job;
    save_sweep(sweep);
    const std::string references_job = record["references_job"];
    const std::string all_jobs = (references_job.empty() ? "" : references_job + ",") + array_job + "," + merge_job;
    if (!references_job.empty())
        out << "submitted references job " << references_job << " (" << (references.size() + size_t(options.batch) - 1) / size_t(options.batch)
            << " indices), then\n";
    out << "submitted array job " << array_job << " (" << (tasks.size() + size_t(options.batch) - 1) / size_t(options.batch)
        << " indices) and merge job " << merge_job << " (after the array)\n"
        << "watch:   squeue -j " << all_jobs << "\n"
        << "account: sacct -j " << all_jobs << "   (where accounting is on)\n"
        << "status:  gilab sweep status " << sweep.directory().string() << "\n"
        << "logs:    " << (sweep.directory() / "logs").string() << std::endl;
}

namespace {

std::string first_word(const std::string& text) { return text.substr(0, text.find(' ')); }

std::string classify(const std::string& slurm_state) {
    static const std::set<std::string> running = {"RUNNING", "COMPLETING", "CONFIGURING", "STAGE_OUT", "RESIZING"};
    static const std::set<std::string> pending = {"PENDING", "REQUEUED", "REQUEUE_FED", "REQUEUE_HOLD", "SUSPENDED",
                                                  "RESV_DEL_HOLD", "SIGNALING"};
    if (running.count(slurm_state)) return "running";
    if (pending.count(slurm_state)) return "pending";
    return "failed";  // ended (FAILED, TIMEOUT, CANCELLED, NODE_FAIL, OUT_OF_MEMORY, PREEMPTED, ...) without a result
}

// "JOBID_INDEX|STATE" lines into a map.
std::map<std::string, std::string> parse_states(const std::string& output) {
    std::map<std::string, std::string> states;
    std::stringstream lines(output);
    for (std::string line; std::getline(lines, line);) {
        const size_t bar = line.find('|');
        if (bar != std::string::npos) states[line.substr(0, bar)] = first_word(line.substr(bar + 1));
    }
    return states;
}

}  // namespace

SlurmTaskStates query_slurm_states(const Sweep& sweep) {
    SlurmTaskStates result;
    std::vector<std::string> job_ids;
    for (const nlohmann::json& s : sweep.submissions)
        for (const char* key : {"references_job", "array_job", "merge_job"})
            if (!s.value(key, std::string()).empty()) job_ids.push_back(s.value(key, std::string()));
    if (job_ids.empty()) return result;
    const std::string jobs = join(job_ids, ",");
    std::map<std::string, std::string> queued, accounted;
    if (program_on_path("squeue")) {
        const ProgramResult r = call_program({"squeue", "-h", "-r", "-j", jobs, "-o", "%i|%T"});
        // squeue refuses ids it no longer knows (all of them finished): nothing queued.
        result.squeue_available = r.exit_code == 0 || r.output.find("Invalid job id") != std::string::npos;
        if (r.exit_code == 0) queued = parse_states(r.output);
    }
    if (program_on_path("sacct")) {
        const ProgramResult r = call_program({"sacct", "-n", "-P", "-X", "-j", jobs, "-o", "JobID,State"});
        result.sacct_available = r.exit_code == 0 && r.output.find("disabled") == std::string::npos;
        if (result.sacct_available) accounted = parse_states(r.output);
    }
    std::set<std::string> queued_jobs;
    for (const auto& [id, state] : queued) queued_jobs.insert(id.substr(0, id.find('_')));
    result.queued_jobs.assign(queued_jobs.begin(), queued_jobs.end());

    for (const nlohmann::json& s : sweep.submissions) {  // later rounds override earlier ones
        const std::string array_job = s.value("array_job", std::string());
        if (array_job.empty()) continue;
        std::ifstream in(s.value("tasks_file", std::string()));
        const int batch = s.value("batch", 1);
        int line_number = 0;
        for (std::string line; std::getline(in, line); ++line_number) {
            std::stringstream words(line);
            std::string name, id;
            words >> name >> id;
            const std::string index = array_job + "_" + std::to_string(line_number / batch);
            std::string state;
            if (auto q = queued.find(index); q != queued.end()) state = classify(q->second);
            else if (auto a = accounted.find(index); a != accounted.end()) state = classify(a->second);
            else if (result.squeue_available) state = "failed";  // left the queue without a result
            if (!state.empty()) result.task_state[name + " " + id] = state;
        }
    }
    return result;
}

}  // namespace gilab
