#include "experiments/runner/task_command.hpp"

#include <charconv>
#include <cstdlib>
#include "core/util/error.hpp"
#include "experiments/runner/experiment.hpp"
#include "experiments/runner/path_reference.hpp"
#include "experiments/runner/spec_runner.hpp"

namespace gilab {

namespace fs = std::filesystem;

const Experiment& declared_experiment_named(const std::string& name) {
    const Experiment& e = ExperimentRegistry::builtin().get(name);  // throws listing the known ones
    if (!e.spec) {
        std::string declared_ones;
        for (const Experiment& other : ExperimentRegistry::builtin().list())
            if (other.spec) declared_ones += (declared_ones.empty() ? "" : ", ") + other.name;
        throw Error(name, "this experiment is not declared as a spec, so it runs only whole (`gilab experiment " + name +
                              "`); declared ones: " + (declared_ones.empty() ? "none" : declared_ones));
    }
    return e;
}

Experiment declared_experiment_with_axes(const std::string& name, const std::vector<std::string>& axes) {
    const Experiment& declared = declared_experiment_named(name);
    return axes.empty() ? declared : declared_experiment(with_extra_axes(*declared.spec, axes));
}

namespace {

int task_id(const std::string& text) {
    int id = -1;
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), id);
    if (ec != std::errc() || end != text.data() + text.size() || id < 0)
        throw Error("run-task", "'" + text + "' is not a task id (a number from `gilab experiment plan`)");
    return id;
}

}  // namespace

int run_task_command(const TaskCommand& c, std::ostream& out) {
    const bool one_task = c.verb == "run-task" || c.verb == "references";
    if (c.arguments.size() != (one_task ? 2u : 1u))
        throw Error(c.verb, one_task ? "needs an experiment name and a task id: " + c.verb + " NAME ID"
                                     : "needs one experiment name: " + c.verb + " NAME");
    const Experiment e = declared_experiment_with_axes(c.arguments[0], c.axes);
    ExperimentContext ctx;
    ctx.quick = c.quick;
    ctx.output_dir = c.results_root / e.name;
    ctx.assets = c.assets;
    ctx.seed = c.seed;
    ctx.threads = c.threads;
    ctx.log = &out;
    if (c.verb == "plan") {
        for (const SpecTask& t : plan_tasks(*e.spec, c.quick)) {
            nlohmann::json line = plan_entry(*e.spec, t, c.quick);
            if (const auto seconds = last_task_seconds(*e.spec, t, ctx)) line["seconds_last_run"] = *seconds;
            out << line.dump() << "\n";
        }
        return 0;
    }
    if (c.verb == "run-task") {
        const int id = task_id(c.arguments[1]);
        // For tests of failure handling (sweeps, job arrays): a task that fails on demand.
        // ($GILAB_TASK_DELAY, a task to kill while it runs, is spec_runner's.)
        if (const char* fail = std::getenv("GILAB_FAIL_TASK"); fail && std::string(fail) == e.name + "/" + std::to_string(id))
            throw Error(e.name + " task " + std::to_string(id), "failed on purpose ($GILAB_FAIL_TASK=" + std::string(fail) + ")");
        run_spec_task(*e.spec, id, ctx);
        out << "wrote " << spec_task_file(ctx.output_dir, id, ctx.quick).string() << "\n";
        return 0;
    }
    if (c.verb == "references") {
        const int count = render_task_references(*e.spec, task_id(c.arguments[1]), ctx);
        out << count << " reference(s) of task " << c.arguments[1] << " in " << reference_store(ctx).string() << "\n";
        return 0;
    }
    const fs::path tasks = spec_task_file(ctx.output_dir, 0, ctx.quick).parent_path();
    if (!fs::is_directory(tasks))
        throw Error(tasks.string(), "no such directory: no task of the " + std::string(c.quick ? "quick" : "full") +
                                        " plan has run under " + c.results_root.string() +
                                        " (run-task writes there; check --results and --quick)");
    Experiment merging = e;
    merging.run = [spec = e.spec](const ExperimentContext& context) { return merge_spec_tasks(*spec, context); };
    run_and_write(merging, ctx);
    out << "wrote " << (ctx.output_dir / "table.md").string() << "\n";
    return 0;
}

}  // namespace gilab
