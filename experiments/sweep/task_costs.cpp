#include "experiments/sweep/task_costs.hpp"

#include <nlohmann/json.hpp>

namespace gilab {

extern const char* const kTaskCostsJson;  // task_costs.json, compiled in (experiments/CMakeLists.txt)

namespace {

const nlohmann::json& costs() {
    static const nlohmann::json table = nlohmann::json::parse(kTaskCostsJson);
    return table;
}

}  // namespace

std::optional<double> longest_task_seconds(const std::string& experiment, bool quick) {
    const nlohmann::json& experiments = costs().at("experiments");
    if (!experiments.contains(experiment)) return std::nullopt;
    const nlohmann::json& entry = experiments.at(experiment);
    const char* key = quick ? "quick_longest_s" : "full_longest_s";
    if (!entry.contains(key) || !entry.at(key).is_number()) return std::nullopt;
    return entry.at(key).get<double>();
}

std::string task_costs_measured_on() { return costs().at("measured_on").get<std::string>(); }

}  // namespace gilab
