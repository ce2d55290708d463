// What is available (techniques, scenes) and process-wide settings (memory budget), as
// `gilab list` shows them and --memory-limit sets them.
#include <pybind11/stl.h>
#include "core/util/memory_budget.hpp"
#include "experiments/runner/result_writers.hpp"
#include "python/bindings.hpp"
#include "scenes/builtin_scenes.hpp"
#include "scenes/scene_library.hpp"
#include "techniques/technique.hpp"

namespace gilab::python {

using namespace pybind11::literals;

void register_catalogue_bindings(py::module_& m) {
    m.def(
        "techniques",
        [] {
            py::list list;
            for (const auto& t : TechniqueRegistry::builtin().list())
                list.append(py::dict("name"_a = t.name, "description"_a = t.description));
            return list;
        },
        "The registered techniques as dicts (name, description), as `gilab list techniques`.");
    m.def(
        "settings",
        [](const std::string& technique) {
            const TechniqueRegistry& registry = TechniqueRegistry::builtin();
            const TechniqueInfo* info = registry.find(technique);
            if (!info) registry.create(technique);  // throws gilab.Error listing the known ones
            py::list list;
            for (const SettingSpec& s : info->settings_schema().specs()) {
                py::dict d("key"_a = s.key, "type"_a = to_string(s.type), "range"_a = s.range_text(), "unit"_a = s.unit,
                           "description"_a = s.description, "quality_knob"_a = s.knob.has_value());
                if (s.default_value.is_null())
                    d["default"] = py::none(), d["derived_default"] = s.derived_default;
                else if (s.default_value.is_boolean())
                    d["default"] = s.default_value.get<bool>();
                else if (s.default_value.is_number_integer())
                    d["default"] = s.default_value.get<int64_t>();
                else if (s.default_value.is_number())
                    d["default"] = s.default_value.get<double>();
                else
                    d["default"] = s.default_value.get<std::string>();
                if (s.type == SettingType::Choice) d["choices"] = s.choices;
                list.append(d);
            }
            return list;
        },
        "technique"_a,
        "A technique's settings as dicts (key, type, default, range, unit, description, quality_knob; choices for a "
        "choice; derived_default when the default depends on the scene or other settings), as `gilab list settings "
        "TECHNIQUE`.");
    m.def(
        "scenes",
        [] {
            py::dict scenes;
            py::list builtin;
            for (const auto& s : builtin_scenes()) builtin.append(py::dict("name"_a = s.name, "description"_a = s.description));
            scenes["builtin"] = builtin;
            scenes["files"] = scene_file_names();
            scenes["directory"] = scenes_directory();
            return scenes;
        },
        "{\"builtin\": [{name, description}], \"files\": [scene file names], \"directory\": where they are}.");
    m.def("git_revision", &git_revision, "The git revision this module was built from (stamped into outputs).");
    m.def(
        "set_memory_limit",
        [](const py::object& limit) {
            if (limit.is_none()) return MemoryBudget::set_limit(0);
            if (py::isinstance<py::str>(limit))
                return MemoryBudget::set_limit(MemoryBudget::parse_size(limit.cast<std::string>(), "memory limit"));
            MemoryBudget::set_limit(limit.cast<uint64_t>());
        },
        "limit"_a, R"doc(Sets the memory budget for everything sized by input (like --memory-limit):
bytes, or a size such as "8G", "512M"; None restores the default (half the
physical memory). Requests beyond it raise gilab.Error before allocating.
)doc");
    m.def("memory_limit", &MemoryBudget::limit, "The memory budget in bytes.");
}

}  // namespace gilab::python
