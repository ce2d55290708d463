#pragma once
// `gilab report`: gathers every results/NAME/results.json and every comparison
// (results/compare/SCENE/results.json) into one self-contained HTML page: a table of
// contents grouped by paper, then each experiment's run line, tables, notes, plots and
// images, then each comparison's table and images, all linked by relative paths.
#include <filesystem>
#include <string>

namespace gilab {

// Writes results_root/report.html; returns the number of experiments included.
// Folders whose names start with '.' (runs in progress) are skipped. Throws Error if
// results_root holds neither an experiment's nor a comparison's results.json, or if one
// of them is malformed.
int write_html_report(const std::filesystem::path& results_root);

// Text made safe inside HTML elements and quoted attributes (< > & " ').
std::string escape_html(const std::string& s);

}  // namespace gilab
