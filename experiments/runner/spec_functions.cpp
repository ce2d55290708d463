#include "experiments/runner/spec_functions.hpp"

#include <mutex>
#include "experiments/runner/experiment_spec.hpp"
#include "scenes/scene_library.hpp"

namespace gilab {

namespace {

template <class F>
std::map<std::string, F>& named() {
    static std::map<std::string, F> functions;
    return functions;
}
std::mutex& registry_mutex() {
    static std::mutex m;
    return m;
}

}  // namespace

const Scene& ProbeCall::scene() const {
    return cache.get<Scene>("scene:" + task.scene, [&] { return open_scene(task.scene, ctx.assets).scene; });
}

const Scene* ProbeCall::scene_or_null(std::string* why) const {
    try {
        return &scene();
    } catch (const Error& e) {
        if (why) *why = e.what();
        return nullptr;
    }
}

const nlohmann::json* TaskResult::row(const std::string& variant) const {
    for (const nlohmann::json& r : rows)
        if (r.value("variant", std::string()) == variant) return &r;
    return nullptr;
}

int SpecReduction::size() const { return ctx.quick ? spec.quick_size : spec.size; }
int SpecReduction::frames() const { return ctx.quick ? spec.quick_frames : spec.frames; }
int SpecReduction::reference_spp() const { return ctx.quick ? spec.quick_reference_spp : spec.reference_spp; }

// Registering the same name again replaces it: each registry built from the same
// register_* functions (the builtin one, a test's) adds the same functions.
void add_probe(const std::string& name, ProbeFunction probe, ProbeReferences references, ProbeReferenceGroup group) {
    std::lock_guard lock(registry_mutex());
    named<ProbeFunction>()[name] = std::move(probe);
    if (references) named<ProbeReferences>()[name] = std::move(references);
    else named<ProbeReferences>().erase(name);
    if (group) named<ProbeReferenceGroup>()[name] = std::move(group);
    else named<ProbeReferenceGroup>().erase(name);
}
void add_reducer(const std::string& name, ReducerFunction reducer) {
    std::lock_guard lock(registry_mutex());
    named<ReducerFunction>()[name] = std::move(reducer);
}
const ProbeFunction* find_probe(const std::string& name) {
    std::lock_guard lock(registry_mutex());
    auto it = named<ProbeFunction>().find(name);
    return it == named<ProbeFunction>().end() ? nullptr : &it->second;
}
const ProbeReferences* find_probe_references(const std::string& name) {
    std::lock_guard lock(registry_mutex());
    auto it = named<ProbeReferences>().find(name);
    return it == named<ProbeReferences>().end() ? nullptr : &it->second;
}
const ProbeReferenceGroup* find_probe_reference_group(const std::string& name) {
    std::lock_guard lock(registry_mutex());
    auto it = named<ProbeReferenceGroup>().find(name);
    return it == named<ProbeReferenceGroup>().end() ? nullptr : &it->second;
}
const ReducerFunction* find_reducer(const std::string& name) {
    std::lock_guard lock(registry_mutex());
    auto it = named<ReducerFunction>().find(name);
    return it == named<ReducerFunction>().end() ? nullptr : &it->second;
}

}  // namespace gilab
