#include "experiments/runner/experiment_spec.hpp"

#include <sstream>
#include "core/util/error.hpp"
#include "experiments/runner/spec_functions.hpp"
#include "techniques/technique.hpp"

namespace gilab {

namespace {

using Source = SpecMeasure::Source;

const std::vector<std::pair<Source, const char*>> kSources = {
    {Source::FrameStat, "frame stat (median over frames)"},
    {Source::PrepareStat, "prepare stat"},
    {Source::RelMse, "relMSE against the path-traced reference"},
    {Source::LastFrameStat, "last frame's stat"},
    {Source::LayerMean, "last frame's layer mean"},
    {Source::ImageDigest, "last frame's layer digest"},
};

const char* to_string(Source source) {
    for (const auto& [s, text] : kSources)
        if (s == source) return text;
    return "?";
}

Source source_named(const std::string& text, const std::string& where) {
    std::string known;
    for (const auto& [s, name] : kSources) {
        if (text == name) return s;
        known += std::string(known.empty() ? "" : ", ") + "'" + name + "'";
    }
    throw Error(where, "unknown measure source '" + text + "' (known: " + known + ")");
}

template <class T>
T field(const nlohmann::json& j, const char* key, T fallback, const std::string& where) {
    if (!j.contains(key)) return fallback;
    try {
        return j.at(key).get<T>();
    } catch (const nlohmann::json::exception&) {
        throw Error(where, std::string("'") + key + "' has the wrong type: " + j.at(key).dump());
    }
}

// A full/quick pair written as {"full": F, "quick": Q}, or one number for both.
void read_pair(const nlohmann::json& j, const char* key, int& full, int& quick, const std::string& where) {
    if (!j.contains(key)) return;
    const nlohmann::json& v = j.at(key);
    if (v.is_number_integer()) {
        full = quick = v.get<int>();
        return;
    }
    full = field(v, "full", full, where + ", " + key);
    quick = field(v, "quick", quick, where + ", " + key);
}

}  // namespace

bool ExperimentSpec::needs_reference() const {
    for (const SpecMeasure& m : measures)
        if (m.source == Source::RelMse) return true;
    return false;
}

bool ExperimentSpec::has_technique_variant() const {
    for (const SpecVariant& v : variants)
        if (!v.is_probe()) return true;
    return false;
}

nlohmann::json ExperimentSpec::to_json() const {
    nlohmann::json j;
    j["name"] = name;
    j["paper"] = paper;
    j["figure"] = figure;
    j["description"] = description;
    j["scenes"] = scenes;
    j["size"] = {{"full", size}, {"quick", quick_size}};
    j["frames"] = {{"full", frames}, {"quick", quick_frames}};
    j["reference_spp"] = {{"full", reference_spp}, {"quick", quick_reference_spp}};
    if (slow.frame_ms > 0) j["slow"] = {{"frame_ms", slow.frame_ms}, {"frames", slow.frames}};
    j["interleave_variants"] = interleave_variants;
    j["variants"] = nlohmann::json::array();
    for (const SpecVariant& v : variants) {
        nlohmann::json jv = {{"name", v.name}, {"settings", v.settings}};
        jv[v.is_probe() ? "probe" : "technique"] = v.is_probe() ? v.probe : v.technique;
        j["variants"].push_back(jv);
    }
    j["axes"] = nlohmann::json::array();
    for (const SpecAxis& a : axes) j["axes"].push_back({{"setting", a.setting}, {"full", a.full}, {"quick", a.quick}});
    j["measures"] = nlohmann::json::array();
    for (const SpecMeasure& m : measures)
        j["measures"].push_back({{"column", m.column}, {"source", to_string(m.source)}, {"key", m.key}});
    if (!reducer.empty()) j["reducer"] = reducer;
    if (!measures.empty())
        j["statistic"] = statistic == FrameStatistic::Mean ? "mean over a task's frames (frame stats)"
                                                           : "median over a task's frames (frame stats)";
    j["notes"] = notes;
    return j;
}

ExperimentSpec ExperimentSpec::from_json(const nlohmann::json& j) {
    if (!j.is_object()) throw Error("experiment spec", "must be an object (a dict), not " + j.dump());
    ExperimentSpec s;
    s.name = field<std::string>(j, "name", "", "experiment spec");
    const std::string where = "experiment spec '" + s.name + "'";
    if (s.name.empty()) throw Error("experiment spec", "needs a 'name'");
    static const std::vector<std::string> known = {
        "name",          "paper",    "figure", "description", "scenes", "size",     "frames",   "reference_spp",
        "slow",          "interleave_variants", "variants", "axes", "measures", "reducer", "notes", "statistic"};
    for (auto it = j.begin(); it != j.end(); ++it)
        if (std::find(known.begin(), known.end(), it.key()) == known.end())
            throw Error(where, "unknown key '" + it.key() + "'");
    s.paper = field<std::string>(j, "paper", "", where);
    s.figure = field<std::string>(j, "figure", s.name, where);
    s.description = field<std::string>(j, "description", "", where);
    s.scenes = field<std::vector<std::string>>(j, "scenes", {}, where);
    read_pair(j, "size", s.size, s.quick_size, where);
    read_pair(j, "frames", s.frames, s.quick_frames, where);
    read_pair(j, "reference_spp", s.reference_spp, s.quick_reference_spp, where);
    if (j.contains("slow")) {
        s.slow.frame_ms = field(j["slow"], "frame_ms", 0.0, where + ", slow");
        s.slow.frames = field(j["slow"], "frames", 0, where + ", slow");
    }
    s.interleave_variants = field(j, "interleave_variants", false, where);
    for (const nlohmann::json& v : field(j, "variants", nlohmann::json::array(), where)) {
        SpecVariant variant;
        variant.name = field<std::string>(v, "name", "", where + ", variant");
        variant.technique = field<std::string>(v, "technique", "", where + ", variant '" + variant.name + "'");
        variant.probe = field<std::string>(v, "probe", "", where + ", variant '" + variant.name + "'");
        variant.settings = field(v, "settings", nlohmann::json::object(), where + ", variant '" + variant.name + "'");
        if (variant.name.empty()) variant.name = variant.technique.empty() ? variant.probe : variant.technique;
        s.variants.push_back(std::move(variant));
    }
    for (const nlohmann::json& a : field(j, "axes", nlohmann::json::array(), where)) {
        SpecAxis axis;
        axis.setting = field<std::string>(a, "setting", "", where + ", axis");
        const std::string at = where + ", axis '" + axis.setting + "'";
        if (a.contains("values")) {
            axis.full = axis.quick = field<std::vector<nlohmann::json>>(a, "values", {}, at);
        } else {
            axis.full = field<std::vector<nlohmann::json>>(a, "full", {}, at);
            axis.quick = field<std::vector<nlohmann::json>>(a, "quick", axis.full, at);
        }
        s.axes.push_back(std::move(axis));
    }
    for (const nlohmann::json& m : field(j, "measures", nlohmann::json::array(), where)) {
        SpecMeasure measure;
        measure.column = field<std::string>(m, "column", "", where + ", measure");
        measure.key = field<std::string>(m, "key", measure.column, where + ", measure '" + measure.column + "'");
        measure.source = source_named(field<std::string>(m, "source", to_string(Source::FrameStat), where), where);
        s.measures.push_back(std::move(measure));
    }
    s.reducer = field<std::string>(j, "reducer", "", where);
    const std::string statistic = field<std::string>(j, "statistic", "median", where);
    if (statistic.rfind("mean", 0) == 0) s.statistic = FrameStatistic::Mean;
    else if (statistic.rfind("median", 0) != 0)
        throw Error(where, "statistic '" + statistic + "' is neither 'median' nor 'mean'");
    s.notes = field<std::vector<std::string>>(j, "notes", {}, where);
    return s;
}

void ExperimentSpec::check() const {
    const std::string where = "experiment spec '" + name + "'";
    if (scenes.empty()) throw Error(where, "no scene");
    if (variants.empty()) throw Error(where, "no variant");
    if (size < 1 || quick_size < 1 || frames < 1 || quick_frames < 1) throw Error(where, "sizes and frames must be ≥ 1");
    if (has_technique_variant() && measures.empty()) throw Error(where, "technique variants need at least one measure");
    if (!reducer.empty() && !find_reducer(reducer)) throw Error(where, "no reducer named '" + reducer + "'");
    for (const SpecVariant& v : variants) {
        const std::string at = where + ", variant '" + v.name + "'";
        if (v.is_probe() == !v.technique.empty())
            throw Error(at, "needs exactly one of a technique and a probe");
        if (!v.settings.is_object()) throw Error(at, "settings must be an object");
        if (v.is_probe()) {
            if (!find_probe(v.probe)) throw Error(at, "no probe named '" + v.probe + "'");
            continue;
        }
        const TechniqueInfo* info = TechniqueRegistry::builtin().find(v.technique);
        if (!info) TechniqueRegistry::builtin().create(v.technique);  // throws listing the known ones
        const SettingsSchema& schema = info->settings_schema();
        Settings given(v.settings, at);
        schema.check_known(given);
        for (const SpecAxis& a : axes) {
            std::vector<std::string> keys;
            if (!a.setting.empty()) keys.push_back(a.setting);
            for (const nlohmann::json& value : a.full)
                if (a.setting.empty() && value.is_object())
                    for (auto it = value.begin(); it != value.end(); ++it) keys.push_back(it.key());
            for (const std::string& key : keys)
                if (!schema.declares(key))
                    throw Error(where, "axis '" + key + "' is not a setting of technique '" + v.technique + "'");
        }
    }
    for (const SpecAxis& a : axes) {
        if (a.full.empty() || a.quick.empty()) throw Error(where, "axis '" + a.setting + "' has no values");
        if (a.setting.empty())
            for (const auto* values : {&a.full, &a.quick})
                for (const nlohmann::json& value : *values)
                    if (!value.is_object())
                        throw Error(where, "an axis without a setting takes objects of settings, not " + value.dump());
    }
}

nlohmann::json SpecTask::to_json() const {
    nlohmann::json j = {{"id", id}, {"scene", scene}, {"axes", axes}};
    for (const TaskVariant& v : variants) {
        nlohmann::json jv = {{"name", v.name}, {"settings", v.settings}};
        jv[v.probe.empty() ? "technique" : "probe"] = v.probe.empty() ? v.technique : v.probe;
        j["variants"].push_back(jv);
    }
    return j;
}

ExperimentSpec with_extra_axes(ExperimentSpec spec, const std::vector<std::string>& axes) {
    for (const std::string& text : axes) {
        const size_t eq = text.find('=');
        if (eq == 0 || eq == std::string::npos || eq + 1 == text.size())
            throw Error("--axis " + text, "give SETTING=V1,V2,… (e.g. radius=0.05,0.1)");
        const std::string setting = text.substr(0, eq);
        const std::string list_text = text.substr(eq + 1);
        if (list_text.back() == ',') throw Error("--axis " + text, "an empty value");
        std::vector<nlohmann::json> values;
        std::stringstream list(list_text);
        for (std::string value; std::getline(list, value, ',');) {
            if (value.empty()) throw Error("--axis " + text, "an empty value");
            // A comma separates values, so a value cannot be a list or an object.
            if (value.front() == '[' || value.front() == '{')
                throw Error("--axis " + text, "values are numbers, true/false or words, not lists or objects");
            const nlohmann::json parsed = nlohmann::json::parse(value, nullptr, /*allow_exceptions=*/false);
            values.push_back(parsed.is_discarded() ? nlohmann::json(value) : parsed);
        }
        bool replaced = false;
        for (SpecAxis& a : spec.axes) {
            if (a.setting == setting) {
                a.full = a.quick = values;
                replaced = true;
            } else if (a.setting.empty() && !a.full.empty() && a.full.front().is_object() &&
                       a.full.front().contains(setting)) {
                throw Error("--axis " + text, "experiment '" + spec.name + "' sets '" + setting +
                                                  "' together with other settings on one axis (a published table's "
                                                  "rows); it cannot be swept on its own");
            }
        }
        if (!replaced) {
            // A technique's schema checks the setting (check() below); a probe takes
            // only the settings its variant gives.
            for (const SpecVariant& v : spec.variants)
                if (v.is_probe() && !v.settings.contains(setting))
                    throw Error("--axis " + text, "variant '" + v.name + "' of experiment '" + spec.name + "' (probe '" +
                                                      v.probe + "') has no setting '" + setting + "' to sweep");
            spec.axes.push_back({setting, values, values});
        }
    }
    spec.check();
    return spec;
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
                if (axis.setting.empty()) p.update(value);
                else p[axis.setting] = value;
                next.push_back(p);
            }
        points = std::move(next);
    }
    auto task_variant = [&](const SpecVariant& v, const nlohmann::json& point, int id) {
        TaskVariant t{v.name, v.technique, v.probe, v.settings};
        for (auto it = point.begin(); it != point.end(); ++it) t.settings[it.key()] = it.value();
        // Values are checked here, for every task, so a bad axis value stops the plan, not
        // the run after hours.
        if (!v.is_probe())
            TechniqueRegistry::builtin().find(v.technique)->settings_schema().check_values(
                Settings(t.settings, "experiment spec '" + spec.name + "', task " + std::to_string(id)));
        return t;
    };
    std::vector<SpecTask> tasks;
    for (const std::string& scene : spec.scenes)
        for (const nlohmann::json& point : points) {
            if (spec.interleave_variants) {
                SpecTask t{int(tasks.size()), scene, point, {}};
                for (const SpecVariant& v : spec.variants) t.variants.push_back(task_variant(v, point, t.id));
                tasks.push_back(std::move(t));
                continue;
            }
            for (const SpecVariant& v : spec.variants) {
                SpecTask t{int(tasks.size()), scene, point, {}};
                t.variants.push_back(task_variant(v, point, t.id));
                tasks.push_back(std::move(t));
            }
        }
    return tasks;
}

}  // namespace gilab
