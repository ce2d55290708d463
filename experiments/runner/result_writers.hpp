#pragma once
// Renders experiment output as CSV, Markdown and JSON text.
#include <string>
#include "experiments/runner/experiment.hpp"

namespace gilab {

std::string to_csv(const ResultTable& table);
std::string to_markdown(const ResultTable& table);
std::string format_cell(const nlohmann::json& value);  // numbers to 4 significant digits
nlohmann::json machine_description();                    // cpu model, cores, memory
std::string git_revision();

}  // namespace gilab
