#include "techniques/technique.hpp"

#include <algorithm>

#include "core/util/error.hpp"
#include "techniques/dag_raycast/dag_raycast_technique.hpp"
#include "techniques/dag_shadows/dag_shadows_technique.hpp"
#include "techniques/lpv/lpv_technique.hpp"
#include "techniques/path_tracer/path_tracer.hpp"
#include "techniques/photon_mapping/photon_technique.hpp"
#include "techniques/vct/vct_technique.hpp"

namespace gilab {

void TechniqueRegistry::add(TechniqueInfo info) {
    if (info.name.empty()) throw Error("technique registry", "a technique needs a name");
    if (!info.create) throw Error("technique registry", "technique '" + info.name + "' has no factory");
    if (!info.settings_schema) throw Error("technique registry", "technique '" + info.name + "' has no settings schema");
    const auto& specs = info.settings_schema().specs();
    if (std::count_if(specs.begin(), specs.end(), [](const SettingSpec& s) { return s.knob.has_value(); }) > 1)
        throw Error("technique registry", "technique '" + info.name + "' declares more than one quality knob");
    if (find(info.name)) throw Error("technique registry", "technique '" + info.name + "' is registered twice");
    techniques_.push_back(std::move(info));
}

const TechniqueInfo* TechniqueRegistry::find(const std::string& name) const {
    for (const TechniqueInfo& t : techniques_)
        if (t.name == name) return &t;
    return nullptr;
}

std::unique_ptr<Technique> TechniqueRegistry::create(const std::string& name) const {
    if (const TechniqueInfo* info = find(name)) return info->create();
    std::string known;
    for (const TechniqueInfo& t : techniques_) known += (known.empty() ? "" : ", ") + t.name;
    throw Error("technique '" + name + "'", "unknown technique (known: " + (known.empty() ? "none" : known) + ")");
}

void report_unused_settings(const Technique& technique, const Settings& settings) {
    settings.report_unused("technique '" + technique.name() + "'");
}

void check_settings_known(const Technique& technique, const Settings& settings) {
    if (const TechniqueInfo* info = TechniqueRegistry::builtin().find(technique.name()))
        info->settings_schema().check_known(settings);
}

void prepare_technique(Technique& technique, const Scene& scene, const Settings& settings) {
    check_settings_known(technique, settings);
    technique.prepare(scene, settings);
    report_unused_settings(technique, settings);
}

std::unique_ptr<Technique> prepare_technique(const std::string& name, const Scene& scene, const Settings& settings) {
    std::unique_ptr<Technique> technique = TechniqueRegistry::builtin().create(name);
    prepare_technique(*technique, scene, settings);
    return technique;
}

const TechniqueRegistry& TechniqueRegistry::builtin() {
    // One explicit line per technique: nothing depends on static initialisers.
    static const TechniqueRegistry registry = [] {
        TechniqueRegistry r;
        register_path_tracer(r);
        register_photon_mapping(r);
        register_vct(r);
        register_dag_shadows(r);
        register_dag_raycast(r);
        register_lpv(r);
        return r;
    }();
    return registry;
}

}  // namespace gilab
