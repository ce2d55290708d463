#include "experiments/runner/experiment_spec.hpp"

#include "core/util/error.hpp"
#include "techniques/technique.hpp"

namespace gilab {

namespace {

const char* to_string(SpecMeasure::Source source) {
    switch (source) {
        case SpecMeasure::Source::FrameStat: return "frame stat (median over frames)";
        case SpecMeasure::Source::PrepareStat: return "prepare stat";
        case SpecMeasure::Source::RelMse: return "relMSE against the path-traced reference";
    }
    return "?";
}

}  // namespace

bool ExperimentSpec::needs_reference() const {
    for (const SpecMeasure& m : measures)
        if (m.source == SpecMeasure::Source::RelMse) return true;
    return false;
}

nlohmann::json ExperimentSpec::to_json() const {
    nlohmann::json j;
    j["name"] = name;
    j["paper"] = paper;
    j["figure"] = figure;
    j["scenes"] = scenes;
    j["size"] = {{"full", size}, {"quick", quick_size}};
    j["frames"] = {{"full", frames}, {"quick", quick_frames}};
    if (needs_reference()) j["reference_spp"] = {{"full", reference_spp}, {"quick", quick_reference_spp}};
    for (const SpecVariant& v : variants)
        j["variants"].push_back({{"name", v.name}, {"technique", v.technique}, {"settings", v.settings}});
    for (const SpecAxis& a : axes) j["axes"].push_back({{"setting", a.setting}, {"full", a.full}, {"quick", a.quick}});
    for (const SpecMeasure& m : measures)
        j["measures"].push_back({{"column", m.column}, {"source", to_string(m.source)}, {"key", m.key}});
    j["statistic"] = "median over a task's frames";
    return j;
}

void ExperimentSpec::check() const {
    const std::string where = "experiment spec '" + name + "'";
    if (scenes.empty()) throw Error(where, "no scene");
    if (variants.empty()) throw Error(where, "no variant");
    if (measures.empty()) throw Error(where, "no measure");
    if (size < 1 || quick_size < 1 || frames < 1 || quick_frames < 1) throw Error(where, "sizes and frames must be ≥ 1");
    for (const SpecVariant& v : variants) {
        const TechniqueInfo* info = TechniqueRegistry::builtin().find(v.technique);
        if (!info) TechniqueRegistry::builtin().create(v.technique);  // throws listing the known ones
        const SettingsSchema& schema = info->settings_schema();
        Settings given(v.settings, where + ", variant '" + v.name + "'");
        schema.check_known(given);
        for (const SpecAxis& a : axes)
            if (!schema.declares(a.setting))
                throw Error(where, "axis '" + a.setting + "' is not a setting of technique '" + v.technique + "'");
    }
    for (const SpecAxis& a : axes)
        if (a.full.empty() || a.quick.empty()) throw Error(where, "axis '" + a.setting + "' has no values");
}

nlohmann::json SpecTask::to_json() const {
    return {{"id", id}, {"scene", scene}, {"variant", variant}, {"technique", technique}, {"axes", axes},
            {"settings", settings}};
}

std::vector<SpecTask> plan_tasks(const ExperimentSpec& spec, bool quick) {
    spec.check();
    // Every combination of axis values, the first axis outermost.
    std::vector<nlohmann::json> points = {nlohmann::json::object()};
    for (const SpecAxis& axis : spec.axes) {
        std::vector<nlohmann::json> next;
        for (const nlohmann::json& point : points)
            for (const nlohmann::json& value : quick ? axis.quick : axis.full) {
                nlohmann::json p = point;
                p[axis.setting] = value;
                next.push_back(p);
            }
        points = std::move(next);
    }
    std::vector<SpecTask> tasks;
    for (const std::string& scene : spec.scenes)
        for (const nlohmann::json& point : points)
            for (const SpecVariant& v : spec.variants) {
                SpecTask t;
                t.id = int(tasks.size());
                t.scene = scene;
                t.variant = v.name;
                t.technique = v.technique;
                t.axes = point;
                t.settings = v.settings;
                for (auto it = point.begin(); it != point.end(); ++it) t.settings[it.key()] = it.value();
                // Values are checked here, for every task, so a bad axis value stops the plan,
                // not the run after hours.
                TechniqueRegistry::builtin().find(v.technique)->settings_schema().check_values(
                    Settings(t.settings, "experiment spec '" + spec.name + "', task " + std::to_string(t.id)));
                tasks.push_back(std::move(t));
            }
    return tasks;
}

}  // namespace gilab
