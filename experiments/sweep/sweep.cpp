#include "experiments/sweep/sweep.hpp"

#include <algorithm>
#include <fstream>
#include <functional>
#include <map>
#include <queue>
#include <set>
#include "core/image/image_io.hpp"
#include "core/util/error.hpp"
#include "experiments/report/html_report.hpp"
#include "experiments/runner/experiment.hpp"
#include "experiments/runner/experiment_batch.hpp"
#include "experiments/runner/spec_runner.hpp"
#include "experiments/runner/task_command.hpp"

namespace gilab {

namespace fs = std::filesystem;

const SweepExperiment& Sweep::experiment(const std::string& name) const {
    std::string key = name + (quick ? " quick" : " full");
    for (const std::string& axis : axes) key += " --axis " + axis;
    auto it = made->find(key);
    if (it == made->end()) {
        SweepExperiment e{declared_experiment_with_axes(name, axes), {}};
        e.plan = plan_tasks(*e.experiment.spec, quick);
        it = made->emplace(key, std::move(e)).first;
    }
    return it->second;
}

nlohmann::json Sweep::to_json() const {
    return {{"experiments", experiments}, {"axes", axes}, {"quick", quick},     {"seed", seed},
            {"results", results_root.string()}, {"assets", assets}, {"gilab", gilab.string()},
            {"on", on},                   {"slurm", slurm},     {"submissions", submissions}};
}

Sweep Sweep::from_json(const nlohmann::json& j) {
    Sweep s;
    s.experiments = j.at("experiments").get<std::vector<std::string>>();
    s.axes = j.value("axes", std::vector<std::string>());
    s.quick = j.at("quick").get<bool>();
    s.seed = j.at("seed").get<uint64_t>();
    s.results_root = j.at("results").get<std::string>();
    s.assets = j.at("assets").get<std::string>();
    s.gilab = j.at("gilab").get<std::string>();
    s.on = j.at("on").get<std::string>();
    s.slurm = j.at("slurm");
    s.submissions = j.at("submissions");
    return s;
}

std::vector<std::string> sweep_experiment_names(const std::vector<std::string>& names) {
    if (names.empty()) throw Error("sweep", "needs experiment names or `all` (see `gilab experiment list`)");
    std::vector<std::string> out;
    auto add = [&out](const std::string& name) {
        if (std::find(out.begin(), out.end(), name) == out.end()) out.push_back(name);
    };
    for (const std::string& name : names) {
        if (name == "all") {
            for (const Experiment& e : ExperimentRegistry::builtin().list())
                if (e.spec) add(e.name);
        } else {
            add(declared_experiment_named(name).name);  // throws naming an unknown or undeclared one
        }
    }
    return out;
}

std::vector<SweepTask> sweep_tasks(const Sweep& sweep) {
    std::vector<SweepTask> tasks;
    for (const std::string& name : sweep.experiments)
        for (const SpecTask& t : sweep.experiment(name).plan) tasks.push_back({name, t.id});
    return tasks;
}

fs::path task_result_file(const Sweep& sweep, const SweepTask& task) {
    return spec_task_file(sweep.results_root / task.experiment, task.id, sweep.quick);
}

namespace {

std::optional<nlohmann::json> task_result(const Sweep& sweep, const SweepTask& task) {
    const SweepExperiment& e = sweep.experiment(task.experiment);
    return read_task_result(*e.experiment.spec, e.plan.at(size_t(task.id)), sweep.quick, sweep.seed,
                            task_result_file(sweep, task));
}

}  // namespace

bool task_done(const Sweep& sweep, const SweepTask& task) { return task_result(sweep, task).has_value(); }

namespace {

std::optional<double> cost_of(const nlohmann::json& record) {
    const auto number = [&](const char* key) { return record.contains(key) && record[key].is_number(); };
    if (number("cpu_seconds") && record.value("threads", 0) == 1) return record["cpu_seconds"].get<double>();
    if (number("seconds")) return record["seconds"].get<double>();
    return std::nullopt;
}

}  // namespace

std::optional<double> task_seconds(const Sweep& sweep, const SweepTask& task) {
    const std::optional<nlohmann::json> result = task_result(sweep, task);
    return result ? cost_of(*result) : std::nullopt;
}

std::optional<double> references_seconds(const Sweep& sweep, const SweepTask& task) {
    std::ifstream in(spec_references_cost_file(sweep.results_root / task.experiment, task.id, sweep.quick));
    if (!in) return std::nullopt;
    try {
        return cost_of(nlohmann::json::parse(in));
    } catch (const nlohmann::json::exception&) {
        return std::nullopt;  // a damaged record estimates nothing
    }
}

double wall_seconds_on(std::vector<double> seconds, int slots) {
    if (slots < 1) throw Error("wall_seconds_on", "needs at least one machine");
    std::sort(seconds.begin(), seconds.end(), std::greater<>());
    // Each machine's finishing time, the one free first on top.
    std::priority_queue<double, std::vector<double>, std::greater<>> free_at;
    for (int i = 0; i < slots; ++i) free_at.push(0.0);
    double wall = 0.0;
    for (double s : seconds) {
        const double end = free_at.top() + s;
        free_at.pop();
        free_at.push(end);
        wall = std::max(wall, end);
    }
    return wall;
}

std::vector<SweepTask> tasks_without_result(const Sweep& sweep) {
    std::vector<SweepTask> pending;
    for (const SweepTask& t : sweep_tasks(sweep))
        if (!task_done(sweep, t)) pending.push_back(t);
    return pending;
}

namespace {

std::vector<std::string> experiment_arguments(const Sweep& sweep, const std::string& verb, const SweepTask& task) {
    std::vector<std::string> args = {"experiment", verb, task.experiment, std::to_string(task.id)};
    if (sweep.quick) args.push_back("--quick");
    for (const std::string& axis : sweep.axes) args.insert(args.end(), {"--axis", axis});
    args.insert(args.end(), {"--seed", std::to_string(sweep.seed), "--results", sweep.results_root.string()});
    return args;
}

}  // namespace

std::vector<std::string> run_task_arguments(const Sweep& sweep, const SweepTask& task) {
    return experiment_arguments(sweep, "run-task", task);
}

std::vector<std::string> references_arguments(const Sweep& sweep, const SweepTask& task) {
    return experiment_arguments(sweep, "references", task);
}

std::vector<SweepTask> reference_tasks(const Sweep& sweep, const std::vector<SweepTask>& tasks) {
    std::set<std::string> groups;
    std::vector<SweepTask> out;
    for (const SweepTask& t : tasks) {
        const SweepExperiment& e = sweep.experiment(t.experiment);
        const std::string group = reference_group(*e.experiment.spec, e.plan.at(size_t(t.id)), sweep.quick);
        if (!group.empty() && groups.insert(group).second) out.push_back(t);
    }
    return out;
}

void save_sweep(const Sweep& sweep) {
    fs::create_directories(sweep.directory());
    write_file_atomically(sweep.directory() / "sweep.json", sweep.to_json().dump(2) + "\n");
}

Sweep load_sweep(const fs::path& sweep_dir) {
    const fs::path file = sweep_dir / "sweep.json";
    std::ifstream in(file);
    if (!in)
        throw Error(file.string(), "no sweep here: `gilab sweep` writes RESULTS/.sweep/sweep.json; give that folder");
    try {
        return Sweep::from_json(nlohmann::json::parse(in));
    } catch (const nlohmann::json::exception& e) {
        throw Error(file.string(), std::string("not a sweep record: ") + e.what());
    }
}

namespace {

void merge_published(const Sweep& sweep, const Experiment& e, std::ostream& out) {
    const fs::path final_dir = sweep.results_root / e.name;
    const fs::path tasks = spec_task_file(final_dir, 0, sweep.quick).parent_path();
    if (!fs::is_directory(tasks)) throw Error(e.name, "no task has a result yet (" + tasks.string() + " does not exist)");
    const fs::path staging = staging_directory(sweep.results_root, e.name);
    fs::remove_all(staging);
    // Hard links: the staging copy costs no space, and the merge replaces files by rename,
    // so the published folder is never written through a link.
    fs::copy(final_dir, staging, fs::copy_options::recursive | fs::copy_options::create_hard_links);
    ExperimentContext ctx;
    ctx.quick = sweep.quick;
    ctx.output_dir = staging;
    ctx.assets = AssetPaths::from_environment(sweep.assets.empty() ? std::nullopt : std::optional(sweep.assets));
    ctx.seed = sweep.seed;
    Experiment merging = e;
    merging.run = [spec = e.spec](const ExperimentContext& context) { return merge_spec_tasks(*spec, context); };
    try {
        const ExperimentOutput output = run_and_write(merging, ctx);
        publish_directory(staging, final_dir);
        const auto missing = output.config["effective"].value("tasks_missing", nlohmann::json::array());
        out << "merged " << e.name << ": " << (final_dir / "table.md").string();
        if (!missing.empty()) out << " (tasks missing: " << missing.dump() << ")";
        out << std::endl;
    } catch (...) {
        std::error_code ec;
        fs::remove_all(staging, ec);
        throw;
    }
}

}  // namespace

int merge_sweep(const Sweep& sweep, std::ostream& out, std::ostream& err) {
    int failures = 0;
    for (const std::string& name : sweep.experiments) {
        try {
            merge_published(sweep, sweep.experiment(name).experiment, out);
        } catch (const Error& e) {
            err << "gilab: sweep: cannot merge " << name << ": " << e.what() << std::endl;
            ++failures;
        }
    }
    const int pages = write_html_report(sweep.results_root);
    out << "wrote " << (sweep.results_root / "report.html").string() << " (" << pages << " experiments)" << std::endl;
    return failures;
}

}  // namespace gilab
