#include "experiments/runner/spec_runner.hpp"

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <fstream>
#include <map>
#include <optional>
#include <set>
#include <thread>
#include "core/image/image_io.hpp"
#include "core/image/image_metrics.hpp"
#include "core/util/format.hpp"
#include "core/util/error.hpp"
#include "core/util/stats.hpp"
#include "experiments/runner/interleaved_render.hpp"
#include "experiments/runner/measures.hpp"
#include "experiments/runner/path_reference.hpp"
#include "experiments/runner/result_writers.hpp"
#include "experiments/runner/spec_functions.hpp"
#include "scenes/scene_library.hpp"
#include "techniques/technique.hpp"

namespace gilab {

namespace fs = std::filesystem;

namespace {

using Source = SpecMeasure::Source;

int size_of(const ExperimentSpec& s, bool quick) { return quick ? s.quick_size : s.size; }
int frames_of(const ExperimentSpec& s, bool quick) { return quick ? s.quick_frames : s.frames; }
int reference_spp_of(const ExperimentSpec& s, bool quick) { return quick ? s.quick_reference_spp : s.reference_spp; }

EyeCamera spec_camera(const Scene& scene, int size) {
    const SceneCamera& c = *scene.camera;
    return EyeCamera::look_at(c.position, c.target, c.up, c.vertical_fov_degrees, size, size);
}

// The reference the relMSE measures of a task's technique variants compare against.
ReferenceView technique_reference(const ExperimentSpec& spec, const Scene& scene, bool quick) {
    return {&scene, spec_camera(scene, size_of(spec, quick)), reference_spp_of(spec, quick)};
}

bool measures_relmse(const ExperimentSpec& spec, const SpecTask& task) {
    const bool technique = std::any_of(task.variants.begin(), task.variants.end(),
                                       [](const TaskVariant& v) { return v.probe.empty(); });
    return technique && std::any_of(spec.measures.begin(), spec.measures.end(),
                                    [](const SpecMeasure& m) { return m.source == Source::RelMse; });
}

// The task's scene, loaded once per run (the cache), or nothing with `problem` said.
const Scene* task_scene(const SpecTask& task, TaskCache& cache, const ExperimentContext& ctx, std::string& problem) {
    try {
        return &cache.get<Scene>("scene:" + task.scene, [&] { return open_scene(task.scene, ctx.assets).scene; });
    } catch (const Error& e) {
        problem = "Scene '" + task.scene + "' skipped: " + std::string(e.what());
        return nullptr;
    }
}

const SpecTask& planned_task(const std::vector<SpecTask>& tasks, const ExperimentSpec& spec, int task_id, bool quick) {
    if (task_id < 0 || task_id >= int(tasks.size()))
        throw Error(spec.name, "no task " + std::to_string(task_id) + " in the " + (quick ? "quick " : "") +
                                   "plan (tasks 0 to " + std::to_string(tasks.size() - 1) +
                                   "; `gilab experiment plan " + spec.name + (quick ? " --quick" : "") +
                                   "` lists them)");
    return tasks[size_t(task_id)];
}

// What identifies a task's work: a result file must match it to be merged. The sizes
// and measures come from the spec, so a spec changed since the task ran is caught.
nlohmann::json task_identity(const ExperimentSpec& spec, const SpecTask& t, bool quick, uint64_t seed) {
    nlohmann::json measures = nlohmann::json::array();
    for (const SpecMeasure& m : spec.measures) measures.push_back({m.column, m.key, int(m.source)});
    return {{"quick", quick},
            {"seed", seed},
            {"statistic", int(spec.statistic)},
            {"task", t.to_json()},
            {"size", size_of(spec, quick)},
            {"frames", frames_of(spec, quick)},
            {"reference_spp", reference_spp_of(spec, quick)},
            {"slow", {spec.slow.frame_ms, spec.slow.frames}},
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
    for (const char* key : {"task", "size", "frames", "reference_spp", "slow", "measure_list", "statistic"})
        if (!result.contains(key) || result[key] != identity[key])
            return std::string("its '") + key + "' differs from this plan's (the spec changed since it ran); run the "
                                                "task again";
    return "";
}

// The columns an axis adds to the default table: its setting, or the keys of its
// objects, each with the unit the technique's schema gives it.
std::vector<std::pair<std::string, std::string>> axis_columns(const ExperimentSpec& spec, const SpecAxis& axis) {
    std::vector<std::string> keys;
    if (!axis.setting.empty()) keys.push_back(axis.setting);
    else
        for (auto it = axis.full.front().begin(); it != axis.full.front().end(); ++it) keys.push_back(it.key());
    const SettingsSchema* schema = nullptr;
    for (const SpecVariant& v : spec.variants)
        if (!v.is_probe()) {
            schema = &TechniqueRegistry::builtin().find(v.technique)->settings_schema();
            break;
        }
    std::vector<std::pair<std::string, std::string>> columns;  // (setting, column)
    for (const std::string& key : keys) {
        std::string unit = schema && schema->declares(key) ? schema->spec(key).unit : "";
        columns.emplace_back(key, unit.empty() ? key : key + " (" + unit + ")");
    }
    return columns;
}

// A short digest of a layer's floats: equal digests mean bit-identical layers.
std::string layer_digest(const Film& film, const std::string& layer) {
    uint64_t h = 1469598103934665603ull;  // FNV-1a over the bytes
    for (float f : film.layer(layer).data) {
        const auto* bytes = reinterpret_cast<const unsigned char*>(&f);
        for (size_t i = 0; i < sizeof f; ++i) h = (h ^ bytes[i]) * 1099511628211ull;
    }
    char text[17];
    std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(h));
    return text;
}

// The technique variants of a task: prepared in turn, then rendered in turn frame by
// frame (A B C A B C …), each measured as the spec says.
std::vector<nlohmann::json> run_technique_variants(const ExperimentSpec& spec, const SpecTask& task,
                                                   const std::vector<const TaskVariant*>& variants, const Scene& scene,
                                                   const ExperimentContext& ctx, nlohmann::json& per_frame_out,
                                                   std::vector<std::string>& files) {
    const int size = size_of(spec, ctx.quick);
    const EyeCamera camera = spec_camera(scene, size);
    const size_t n = variants.size();
    std::vector<std::unique_ptr<Technique>> techniques;
    std::vector<Stats> prepared;
    for (const TaskVariant* v : variants) {
        nlohmann::json settings = v->settings;
        if (!settings.contains("seed")) settings["seed"] = ctx.seed;
        Settings given(settings, spec.name + " task " + std::to_string(task.id) + " (" + v->name + ")");
        techniques.push_back(prepare_technique(v->technique, scene, given));
        prepared.push_back(techniques.back()->stats());
    }
    std::vector<std::string> keys;
    for (const SpecMeasure& m : spec.measures)
        if (m.source == Source::FrameStat && std::find(keys.begin(), keys.end(), m.key) == keys.end())
            keys.push_back(m.key);
    const InterleavedRender rendered =
        render_interleaved(techniques, ViewSet::mono(camera), frames_of(spec, ctx.quick), keys, spec.slow);
    std::optional<Film> reference;  // rendered (or read from the cache) once per task
    std::vector<nlohmann::json> rows;
    for (size_t v = 0; v < n; ++v) {
        const InterleavedRun& run = rendered.runs[v];
        const Film& film = run.films.at(0);
        nlohmann::json row = {{"variant", variants[v]->name}};
        for (const SpecMeasure& m : spec.measures) {
            switch (m.source) {
                case Source::FrameStat:
                    row[m.column] = spec.statistic == FrameStatistic::Mean ? mean(run.per_frame.at(m.key))
                                                                           : median(run.per_frame.at(m.key));
                    break;
                case Source::PrepareStat: row[m.column] = prepared[v].get(m.key); break;
                case Source::LastFrameStat: row[m.column] = run.last.get(m.key); break;
                case Source::LayerMean: row[m.column] = mean_value(film, m.key); break;
                case Source::ImageDigest: row[m.column] = layer_digest(film, m.key); break;
                case Source::RelMse: {
                    if (!reference) reference = path_reference(ctx, technique_reference(spec, scene, ctx.quick), files);
                    row[m.column] = relative_mse(film, *reference, m.key);
                    break;
                }
            }
        }
        row["frames"] = rendered.frames;
        per_frame_out[variants[v]->name] = run.per_frame;
        rows.push_back(std::move(row));
    }
    return rows;
}

// For tests of killed tasks: with $GILAB_TASK_DELAY=NAME/ID:SECONDS the task waits that
// long after its work, before its result is written, so a kill then loses the work done.
void wait_if_asked(const ExperimentSpec& spec, const SpecTask& task, const ExperimentContext& ctx) {
    const char* delay = std::getenv("GILAB_TASK_DELAY");
    const std::string key = spec.name + "/" + std::to_string(task.id) + ":";
    if (!delay || std::string(delay).rfind(key, 0) != 0) return;
    const double seconds = std::atof(delay + key.size());
    ctx.say("waiting " + std::to_string(seconds) + " s before writing the result ($GILAB_TASK_DELAY)");
    std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
}

// Task `task`: run its variants, write its file.
nlohmann::json run_planned_task(const ExperimentSpec& spec, const SpecTask& task, TaskCache& cache,
                                const ExperimentContext& ctx) {
    fs::create_directories(ctx.output_dir);  // the reference cache and tasks/ live there
    Stopwatch watch;
    const double cpu_start = process_cpu_seconds();
    std::string names;
    for (const TaskVariant& v : task.variants) names += (names.empty() ? "" : ", ") + v.name;
    ctx.say("task " + std::to_string(task.id) + ": " + task.scene + ", " + names + ", " + task.axes.dump());
    nlohmann::json result = task_identity(spec, task, ctx.quick, ctx.seed);
    nlohmann::json rows = nlohmann::json::array(), notes = nlohmann::json::array(), files = nlohmann::json::array();
    nlohmann::json per_frame = nlohmann::json::object();
    std::vector<const TaskVariant*> techniques;
    for (const TaskVariant& v : task.variants)
        if (v.probe.empty()) techniques.push_back(&v);
    if (!techniques.empty()) {
        // A scene that cannot be loaded (a shared asset not installed) leaves the task
        // without rows and says why, as the probes do.
        std::string problem;
        const Scene* scene = task_scene(task, cache, ctx, problem);
        if (!scene) notes.push_back(problem);
        std::vector<std::string> reference_files;
        if (scene)
            for (nlohmann::json& row : run_technique_variants(spec, task, techniques, *scene, ctx, per_frame, reference_files))
                rows.push_back(std::move(row));
        for (std::string& f : reference_files) files.push_back(std::move(f));
    }
    for (const TaskVariant& v : task.variants) {
        if (v.probe.empty()) continue;
        const ProbeCall call{spec, task, v, ctx, size_of(spec, ctx.quick), frames_of(spec, ctx.quick),
                             reference_spp_of(spec, ctx.quick), cache};
        ProbeOutput out = (*find_probe(v.probe))(call);
        for (nlohmann::json& row : out.rows) {
            if (!row.contains("variant")) row["variant"] = v.name;
            rows.push_back(std::move(row));
        }
        for (std::string& note : out.notes) notes.push_back(std::move(note));
        for (std::string& file : out.files) files.push_back(std::move(file));
    }
    result["rows"] = rows;
    result["seconds"] = watch.elapsed_ms() / 1000.0;
    result["cpu_seconds"] = process_cpu_seconds() - cpu_start;
    result["notes"] = notes;
    result["files"] = files;
    result["per_frame"] = per_frame;
    result["git_revision"] = git_revision();
    const nlohmann::json machine = machine_description();
    result["threads"] = ctx.threads > 0 ? ctx.threads : int(machine["tbb_threads"]);
    result["machine"] = machine.value("cpu", std::string("unknown CPU"));
    const fs::path file = spec_task_file(ctx.output_dir, task.id, ctx.quick);
    wait_if_asked(spec, task, ctx);
    fs::create_directories(file.parent_path());
    write_file_atomically(file, result.dump(2) + "\n");
    return result;
}

}  // namespace

ResultTable SpecReduction::default_table() const {
    ResultTable table;
    table.title = spec.figure + " — " + spec.description;
    table.columns = {"scene"};
    std::vector<std::pair<std::string, std::string>> axes;
    for (const SpecAxis& a : spec.axes)
        for (auto& column : axis_columns(spec, a)) axes.push_back(column);
    for (const auto& [setting, column] : axes) table.columns.push_back(column);
    table.columns.push_back("variant");
    for (const SpecMeasure& m : spec.measures) table.columns.push_back(m.column);
    const size_t measured_from = table.columns.size();
    for (const TaskResult& t : tasks)
        for (const nlohmann::json& row : t.rows)
            for (auto it = row.begin(); it != row.end(); ++it)
                if (it.key() != "variant" && it.key() != "frames" &&
                    std::find(table.columns.begin() + long(measured_from), table.columns.end(), it.key()) ==
                        table.columns.end() &&
                    std::find(table.columns.begin(), table.columns.begin() + long(measured_from), it.key()) ==
                        table.columns.begin() + long(measured_from))
                    table.columns.push_back(it.key());
    if (spec.has_technique_variant()) table.columns.push_back("frames");
    for (const TaskResult& t : tasks)
        for (const nlohmann::json& measured : t.rows) {
            nlohmann::json row = {{"scene", t.task.scene}};
            for (const auto& [setting, column] : axes) row[column] = t.task.axes.value(setting, nlohmann::json());
            for (auto it = measured.begin(); it != measured.end(); ++it) row[it.key()] = it.value();
            for (const std::string& c : table.columns)
                if (!row.contains(c)) row[c] = nullptr;
            table.rows.push_back(std::move(row));
        }
    return table;
}

fs::path spec_task_file(const fs::path& output_dir, int task_id, bool quick) {
    return output_dir / "tasks" / (quick ? "quick" : "full") / (std::to_string(task_id) + ".json");
}

fs::path spec_references_cost_file(const fs::path& output_dir, int task_id, bool quick) {
    return output_dir / "tasks" / (quick ? "quick" : "full") / "references" / (std::to_string(task_id) + ".json");
}

std::optional<nlohmann::json> read_task_result(const ExperimentSpec& spec, const SpecTask& task, bool quick,
                                               uint64_t seed, const fs::path& file) {
    std::ifstream in(file);
    if (!in) return std::nullopt;
    nlohmann::json result = nlohmann::json::parse(in, nullptr, /*allow_exceptions=*/false);
    if (result.is_discarded() || !result.is_object() ||
        !identity_mismatch(result, task_identity(spec, task, quick, seed), quick).empty())
        return std::nullopt;
    return result;
}

nlohmann::json run_spec_task(const ExperimentSpec& spec, int task_id, const ExperimentContext& ctx) {
    const std::vector<SpecTask> tasks = plan_tasks(spec, ctx.quick);
    TaskCache cache;
    return run_planned_task(spec, planned_task(tasks, spec, task_id, ctx.quick), cache, ctx);
}

std::string reference_group(const ExperimentSpec& spec, const SpecTask& task, bool quick) {
    std::set<std::string> groups;
    if (measures_relmse(spec, task))
        groups.insert(task.scene + " " + std::to_string(size_of(spec, quick)) + "px " +
                      std::to_string(reference_spp_of(spec, quick)) + "spp");
    ExperimentContext plan_only;  // the group functions load nothing
    plan_only.quick = quick;
    TaskCache unused;
    for (const TaskVariant& v : task.variants) {
        if (v.probe.empty() || !find_probe_references(v.probe)) continue;
        const ProbeReferenceGroup* group = find_probe_reference_group(v.probe);
        const ProbeCall call{spec, task, v, plan_only, size_of(spec, quick), frames_of(spec, quick),
                             reference_spp_of(spec, quick), unused};
        groups.insert(group ? (*group)(call) : spec.name + "/" + std::to_string(task.id));
    }
    groups.erase("");
    if (groups.empty()) return "";
    // References of several kinds: the task renders all of its own.
    return groups.size() == 1 ? *groups.begin() : spec.name + "/" + std::to_string(task.id);
}

nlohmann::json plan_entry(const ExperimentSpec& spec, const SpecTask& task, bool quick) {
    nlohmann::json entry = task.to_json();
    if (const std::string group = reference_group(spec, task, quick); !group.empty()) entry["references"] = group;
    return entry;
}

int render_task_references(const ExperimentSpec& spec, int task_id, const ExperimentContext& ctx) {
    const std::vector<SpecTask> tasks = plan_tasks(spec, ctx.quick);
    const SpecTask& task = planned_task(tasks, spec, task_id, ctx.quick);
    Stopwatch watch;
    const double cpu_start = process_cpu_seconds();
    TaskCache cache;
    std::vector<std::string> files;
    if (measures_relmse(spec, task)) {
        std::string problem;
        if (const Scene* scene = task_scene(task, cache, ctx, problem))
            path_reference(ctx, technique_reference(spec, *scene, ctx.quick), files);
        else
            ctx.say(problem);
    }
    for (const TaskVariant& v : task.variants) {
        const ProbeReferences* references = v.probe.empty() ? nullptr : find_probe_references(v.probe);
        if (!references) continue;
        const ProbeCall call{spec, task, v, ctx, size_of(spec, ctx.quick), frames_of(spec, ctx.quick),
                             reference_spp_of(spec, ctx.quick), cache};
        for (const ReferenceView& view : (*references)(call)) path_reference(ctx, view, files);
    }
    // What rendering them cost, for the sweep's time figures (the task results do not hold it).
    // A later run (a resume) finds them in the store: the first run's record is kept.
    const fs::path cost_file = spec_references_cost_file(ctx.output_dir, task.id, ctx.quick);
    if (fs::exists(cost_file)) return int(files.size());
    nlohmann::json cost = {{"seconds", watch.elapsed_ms() / 1000.0},
                           {"cpu_seconds", process_cpu_seconds() - cpu_start},
                           {"threads", ctx.threads > 0 ? ctx.threads : int(machine_description()["tbb_threads"])},
                           {"references", files.size()}};
    fs::create_directories(cost_file.parent_path());
    write_file_atomically(cost_file, cost.dump(2) + "\n");
    return int(files.size());
}

ExperimentOutput merge_spec_tasks(const ExperimentSpec& spec, const ExperimentContext& ctx) {
    const std::vector<SpecTask> tasks = plan_tasks(spec, ctx.quick);
    SpecReduction reduction{spec, ctx, {}};
    std::vector<int> missing;
    std::set<std::string> revisions, threads, machines;
    std::vector<std::string> task_notes, task_files;
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
        TaskResult r{task, {}, {}, {}};
        try {
            r.rows = result.at("rows").get<std::vector<nlohmann::json>>();
            r.notes = result.at("notes").get<std::vector<std::string>>();
            r.files = result.at("files").get<std::vector<std::string>>();
        } catch (const nlohmann::json::exception&) {
            throw Error(file.string(), "a task result without its rows, notes and files; run the task again");
        }
        for (const nlohmann::json& row : r.rows)
            for (const SpecMeasure& m : spec.measures)
                if (!spec.variants.empty() && !row.contains(m.column) && row.contains("frames"))
                    throw Error(file.string(), "a task result without the measure '" + m.column + "'; run the task again");
        for (const std::string& note : r.notes)
            if (std::find(task_notes.begin(), task_notes.end(), note) == task_notes.end()) task_notes.push_back(note);
        for (const std::string& f : r.files)
            if (std::find(task_files.begin(), task_files.end(), f) == task_files.end()) task_files.push_back(f);
        machines.insert(result.value("machine", std::string("unknown")));
        revisions.insert(result.value("git_revision", std::string("unknown")));
        threads.insert(std::to_string(result.value("threads", 0)));
        reduction.tasks.push_back(std::move(r));
    }
    if (reduction.tasks.empty())
        throw Error(spec.name, "no task has run yet (" + spec_task_file(ctx.output_dir, 0, ctx.quick).parent_path().string() +
                                   " holds none of the " + std::to_string(tasks.size()) + " tasks)");
    ExperimentOutput out;
    if (spec.reducer.empty()) {
        out.tables.push_back(reduction.default_table());
    } else {
        out = (*find_reducer(spec.reducer))(reduction);
    }
    out.config = spec.to_json();
    out.config["effective"] = {{"quick", ctx.quick},
                               {"size", size_of(spec, ctx.quick)},
                               {"frames", frames_of(spec, ctx.quick)},
                               {"tasks", tasks.size()}};
    out.config["effective"]["reference_spp"] = reference_spp_of(spec, ctx.quick);
    out.config["effective"]["tasks_merged"] = tasks.size() - missing.size();
    out.config["effective"]["tasks_missing"] = missing;
    out.config["effective"]["task_revisions"] = revisions;
    out.config["effective"]["task_threads"] = threads;
    out.config["effective"]["task_machines"] = machines;
    std::vector<std::string> notes = spec.notes;
    notes.insert(notes.end(), out.notes.begin(), out.notes.end());
    notes.insert(notes.end(), task_notes.begin(), task_notes.end());
    out.notes = std::move(notes);
    for (const std::string& f : task_files)
        if (std::find(out.files.begin(), out.files.end(), f) == out.files.end()) out.files.push_back(f);
    if (!missing.empty()) {
        std::string list;
        for (int id : missing) list += (list.empty() ? "" : ", ") + std::to_string(id);
        out.notes.push_back("Incomplete: " + std::to_string(missing.size()) + " of " + std::to_string(tasks.size()) +
                            " tasks have not run (" + list + ").");
    }
    out.notes.push_back("Merged from " + std::to_string(tasks.size() - missing.size()) + " task files (" +
                        spec_task_file(ctx.output_dir, 0, ctx.quick).parent_path().filename().string() +
                        " plan) measured at revision " + join(revisions) + " with " + join(threads) +
                        " threads on " + join(machines) + "; the header above names the merging run.");
    if (revisions.size() > 1 || threads.size() > 1 || machines.size() > 1)
        out.notes.push_back("Tasks ran at more than one revision, thread count or machine: times are comparable only "
                            "within one.");
    return out;
}

std::optional<double> last_task_seconds(const ExperimentSpec& spec, const SpecTask& task, const ExperimentContext& ctx) {
    const fs::path file = spec_task_file(ctx.output_dir, task.id, ctx.quick);
    if (!fs::exists(file)) return std::nullopt;
    try {
        std::ifstream in(file);
        const nlohmann::json result = nlohmann::json::parse(in);
        if (!identity_mismatch(result, task_identity(spec, task, ctx.quick, ctx.seed), ctx.quick).empty() ||
            !result.contains("seconds"))
            return std::nullopt;
        return result.at("seconds").get<double>();
    } catch (const nlohmann::json::exception&) {
        return std::nullopt;  // an unreadable file estimates nothing; merge reports it
    }
}

ExperimentOutput run_spec(const ExperimentSpec& spec, const ExperimentContext& ctx) {
    const std::vector<SpecTask> tasks = plan_tasks(spec, ctx.quick);
    // A fresh run: task files of an earlier run would be merged as if from this one.
    fs::remove_all(spec_task_file(ctx.output_dir, 0, ctx.quick).parent_path());
    // One plan, one cache: each scene (and whatever else the probes share) is loaded once
    // for all tasks.
    TaskCache cache;
    for (const SpecTask& task : tasks) run_planned_task(spec, task, cache, ctx);
    return merge_spec_tasks(spec, ctx);
}

}  // namespace gilab
