#pragma once
// `gilab report`: gathers every results/NAME/results.json into one HTML page.
#include <filesystem>

namespace gilab {

// Writes results_root/report.html; returns the number of experiments included.
// Throws Error if results_root holds no results.json.
int write_html_report(const std::filesystem::path& results_root);

}  // namespace gilab
