#include "experiments/runner/spec_runner.hpp"

#include <algorithm>
#include <fstream>
#include <map>
#include <optional>
#include <set>
#include "core/image/image_io.hpp"
#include "core/image/image_metrics.hpp"
#include "core/util/error.hpp"
#include "core/util/stats.hpp"
#include "experiments/runner/path_reference.hpp"
#include "experiments/runner/result_writers.hpp"
#include "scenes/scene_library.hpp"
#include "techniques/technique.hpp"

namespace gilab {

namespace fs = std::filesystem;

namespace {

// The middle value; the mean of the two middle ones for an even count.
double median(std::vector<double> v) {
    if (v.empty()) return 0.0;
    std::sort(v.begin(), v.end());
    const size_t h = v.size() / 2;
    return v.size() % 2 ? v[h] : 0.5 * (v[h - 1] + v[h]);
}

int size_of(const ExperimentSpec& s, bool quick) { return quick ? s.quick_size : s.size; }
int frames_of(const ExperimentSpec& s, bool quick) { return quick ? s.quick_frames : s.frames; }
int reference_spp_of(const ExperimentSpec& s, bool quick) { return quick ? s.quick_reference_spp : s.reference_spp; }

EyeCamera spec_camera(const Scene& scene, int size) {
    const SceneCamera& c = *scene.camera;
    return EyeCamera::look_at(c.position, c.target, c.up, c.vertical_fov_degrees, size, size);
}

// What identifies a task's work: a result file must match it to be merged. The sizes
// and measures come from the spec, so a spec changed since the task ran is caught.
nlohmann::json task_identity(const ExperimentSpec& spec, const SpecTask& t, bool quick, uint64_t seed) {
    nlohmann::json measures = nlohmann::json::array();
    for (const SpecMeasure& m : spec.measures) measures.push_back({m.column, m.key, int(m.source)});
    return {{"quick", quick},
            {"seed", seed},
            {"task", t.to_json()},
            {"size", size_of(spec, quick)},
            {"frames", frames_of(spec, quick)},
            {"reference_spp", spec.needs_reference() ? reference_spp_of(spec, quick) : 0},
            {"measure_list", measures}};
}

// Why `result` (read from `file`) is not task `t`'s, or "" when it is.
std::string identity_mismatch(const nlohmann::json& result, const nlohmann::json& identity, bool quick) {
    if (!result.contains("quick") || result["quick"] != identity["quick"])
        return std::string("it was written ") + (quick ? "without" : "with") + " --quick; merge " +
               (quick ? "without" : "with") + " --quick to use it";
    if (!result.contains("seed") || result["seed"] != identity["seed"])
        return "it was written with --seed " + result.value("seed", nlohmann::json()).dump() + ", not " +
               identity["seed"].dump();
    for (const char* key : {"task", "size", "frames", "reference_spp", "measure_list"})
        if (!result.contains(key) || result[key] != identity[key])
            return std::string("its '") + key + "' differs from this plan's (the spec changed since it ran); run the "
                                                "task again";
    return "";
}

// An axis's table column: its setting with the unit the technique's schema gives it.
std::string axis_column(const ExperimentSpec& spec, const SpecAxis& axis) {
    const TechniqueInfo* info = TechniqueRegistry::builtin().find(spec.variants.at(0).technique);
    const SettingSpec& setting = info->settings_schema().spec(axis.setting);
    return setting.unit.empty() ? axis.setting : axis.setting + " (" + setting.unit + ")";
}

}  // namespace

fs::path spec_task_file(const fs::path& output_dir, int task_id, bool quick) {
    return output_dir / "tasks" / (quick ? "quick" : "full") / (std::to_string(task_id) + ".json");
}

namespace {
// Task `task` on `scene` (already loaded): prepare, render, measure, write its file.
nlohmann::json run_planned_task(const ExperimentSpec& spec, const SpecTask& task, const Scene& scene,
                                const ExperimentContext& ctx);
}  // namespace

nlohmann::json run_spec_task(const ExperimentSpec& spec, int task_id, const ExperimentContext& ctx) {
    const std::vector<SpecTask> tasks = plan_tasks(spec, ctx.quick);
    if (task_id < 0 || task_id >= int(tasks.size()))
        throw Error(spec.name, "no task " + std::to_string(task_id) + " in the " + (ctx.quick ? "quick " : "") +
                                   "plan (tasks 0 to " + std::to_string(tasks.size() - 1) +
                                   "; `gilab experiment plan " + spec.name + (ctx.quick ? " --quick" : "") +
                                   "` lists them)");
    const SpecTask& task = tasks[size_t(task_id)];
    return run_planned_task(spec, task, open_scene(task.scene, ctx.assets).scene, ctx);
}

namespace {
nlohmann::json run_planned_task(const ExperimentSpec& spec, const SpecTask& task, const Scene& scene,
                                const ExperimentContext& ctx) {
    fs::create_directories(ctx.output_dir);  // the reference cache and tasks/ live there
    const int size = size_of(spec, ctx.quick), frames = frames_of(spec, ctx.quick);
    const EyeCamera camera = spec_camera(scene, size);
    nlohmann::json settings = task.settings;
    if (!settings.contains("seed")) settings["seed"] = ctx.seed;
    Settings given(settings, spec.name + " task " + std::to_string(task.id) + " (" + task.variant + ")");
    ctx.say("task " + std::to_string(task.id) + ": " + task.scene + ", " + task.variant + ", " + task.axes.dump());
    std::unique_ptr<Technique> technique = prepare_technique(task.technique, scene, given);
    const Stats prepared = technique->stats();

    std::map<std::string, std::vector<double>> per_frame;
    std::vector<Film> films;
    for (int f = 0; f < frames; ++f) {
        technique->render(ViewSet::mono(camera), films);
        const Stats stats = technique->stats();
        for (const SpecMeasure& m : spec.measures)
            if (m.source == SpecMeasure::Source::FrameStat) per_frame[m.key].push_back(stats.get(m.key));
    }
    std::optional<Film> reference;  // rendered (or read from the cache) once per task
    nlohmann::json measures = nlohmann::json::object();
    for (const SpecMeasure& m : spec.measures) {
        switch (m.source) {
            case SpecMeasure::Source::FrameStat: measures[m.column] = median(per_frame[m.key]); break;
            case SpecMeasure::Source::PrepareStat: measures[m.column] = prepared.get(m.key); break;
            case SpecMeasure::Source::RelMse: {
                std::vector<std::string> files;
                if (!reference) reference = path_reference(ctx, scene, camera, reference_spp_of(spec, ctx.quick), files);
                measures[m.column] = relative_mse(films.at(0), *reference, m.key);
                break;
            }
        }
    }
    nlohmann::json result = task_identity(spec, task, ctx.quick, ctx.seed);
    result["frames"] = frames;
    result["size"] = size;
    result["measures"] = measures;
    result["per_frame"] = per_frame;
    result["git_revision"] = git_revision();
    const nlohmann::json machine = machine_description();
    result["threads"] = ctx.threads > 0 ? ctx.threads : int(machine["tbb_threads"]);
    result["machine"] = machine.value("cpu", std::string("unknown CPU"));
    const fs::path file = spec_task_file(ctx.output_dir, task.id, ctx.quick);
    fs::create_directories(file.parent_path());
    write_file_atomically(file, result.dump(2) + "\n");
    return result;
}
}  // namespace

ExperimentOutput merge_spec_tasks(const ExperimentSpec& spec, const ExperimentContext& ctx) {
    const std::vector<SpecTask> tasks = plan_tasks(spec, ctx.quick);
    ExperimentOutput out;
    ResultTable table;
    table.title = spec.figure + " — " + spec.description;
    table.columns = {"scene"};
    for (const SpecAxis& a : spec.axes) table.columns.push_back(axis_column(spec, a));
    table.columns.push_back("variant");
    for (const SpecMeasure& m : spec.measures) table.columns.push_back(m.column);
    table.columns.push_back("frames");

    std::vector<int> missing;
    std::set<std::string> revisions, threads, machines;
    for (const SpecTask& task : tasks) {
        const fs::path file = spec_task_file(ctx.output_dir, task.id, ctx.quick);
        if (!fs::exists(file)) {
            missing.push_back(task.id);
            continue;
        }
        std::ifstream in(file);
        nlohmann::json result;
        try {
            result = nlohmann::json::parse(in);
        } catch (const nlohmann::json::exception& e) {
            throw Error(file.string(), std::string("not a task result: ") + e.what());
        }
        const std::string mismatch = identity_mismatch(result, task_identity(spec, task, ctx.quick, ctx.seed), ctx.quick);
        if (!mismatch.empty())
            throw Error(file.string(), "not a result of task " + std::to_string(task.id) + " of this plan: " + mismatch);
        nlohmann::json row;
        row["scene"] = task.scene;
        for (const SpecAxis& a : spec.axes) row[axis_column(spec, a)] = task.axes.at(a.setting);
        row["variant"] = task.variant;
        try {
            for (const SpecMeasure& m : spec.measures) row[m.column] = result.at("measures").at(m.column);
            row["frames"] = result.at("frames");
        } catch (const nlohmann::json::exception&) {
            throw Error(file.string(), "a task result without every measure of the spec; run the task again");
        }
        machines.insert(result.value("machine", std::string("unknown")));
        table.rows.push_back(std::move(row));
        revisions.insert(result.value("git_revision", std::string("unknown")));
        threads.insert(std::to_string(result.value("threads", 0)));
    }
    if (table.rows.empty())
        throw Error(spec.name, "no task has run yet (" + spec_task_file(ctx.output_dir, 0, ctx.quick).parent_path().string() +
                                   " holds none of the " +
                                   std::to_string(tasks.size()) + " tasks)");
    out.tables.push_back(std::move(table));
    out.config = spec.to_json();
    out.config["effective"] = {{"quick", ctx.quick},
                               {"size", size_of(spec, ctx.quick)},
                               {"frames", frames_of(spec, ctx.quick)},
                               {"tasks", tasks.size()}};
    if (spec.needs_reference()) out.config["effective"]["reference_spp"] = reference_spp_of(spec, ctx.quick);
    out.config["effective"]["tasks_merged"] = tasks.size() - missing.size();
    out.config["effective"]["tasks_missing"] = missing;
    out.config["effective"]["task_revisions"] = revisions;
    out.config["effective"]["task_threads"] = threads;
    out.config["effective"]["task_machines"] = machines;
    out.notes = spec.notes;
    if (!missing.empty()) {
        std::string list;
        for (int id : missing) list += (list.empty() ? "" : ", ") + std::to_string(id);
        out.notes.push_back("Incomplete: " + std::to_string(missing.size()) + " of " + std::to_string(tasks.size()) +
                            " tasks have not run (" + list + ").");
    }
    auto joined = [](const std::set<std::string>& values) {
        std::string out;
        for (const auto& v : values) out += (out.empty() ? "" : ", ") + v;
        return out;
    };
    out.notes.push_back("Merged from " + std::to_string(tasks.size() - missing.size()) + " task files (" +
                        spec_task_file(ctx.output_dir, 0, ctx.quick).parent_path().filename().string() +
                        " plan) measured at revision " + joined(revisions) + " with " + joined(threads) +
                        " threads on " + joined(machines) + "; the header above names the merging run.");
    if (revisions.size() > 1 || threads.size() > 1 || machines.size() > 1)
        out.notes.push_back("Tasks ran at more than one revision, thread count or machine: times are comparable only "
                            "within one.");
    return out;
}

ExperimentOutput run_spec(const ExperimentSpec& spec, const ExperimentContext& ctx) {
    const std::vector<SpecTask> tasks = plan_tasks(spec, ctx.quick);
    // A fresh run: task files of an earlier run would be merged as if from this one.
    fs::remove_all(spec_task_file(ctx.output_dir, 0, ctx.quick).parent_path());
    // One plan, and each scene loaded once for all of its tasks.
    std::map<std::string, Scene> scenes;
    for (const SpecTask& task : tasks) {
        auto loaded = scenes.find(task.scene);
        if (loaded == scenes.end()) loaded = scenes.emplace(task.scene, open_scene(task.scene, ctx.assets).scene).first;
        run_planned_task(spec, task, loaded->second, ctx);
    }
    return merge_spec_tasks(spec, ctx);
}

}  // namespace gilab
