#pragma once
// Running one experiment in quick mode from a test, with the checks every experiment
// must pass: its three files are written, each plot it declares is drawn (when gnuplot
// is there), and every row of every table holds every column.
#include <gtest/gtest.h>
#include <filesystem>
#include <initializer_list>
#include <string>
#include "experiments/runner/experiment.hpp"
#include "experiments/runner/plot.hpp"
#include "tests/test_support.hpp"

namespace gilab::test {

// A registry holding the given groups of experiments (register_*_experiments).
inline ExperimentRegistry registry_with(std::initializer_list<void (*)(ExperimentRegistry&)> groups) {
    ExperimentRegistry registry;
    for (auto add : groups) add(registry);
    return registry;
}

// A test name from an experiment name ("vct-table1" → "vct_table1").
inline std::string test_name_of(const testing::TestParamInfo<const char*>& info) {
    std::string name = info.param;
    for (char& c : name)
        if (c == '-') c = '_';
    return name;
}

inline ExperimentOutput run_quick_experiment(const ExperimentRegistry& registry, const std::string& name) {
    namespace fs = std::filesystem;
    ExperimentContext ctx;
    ctx.quick = true;
    ctx.output_dir = temp_dir("quick_experiment_" + name);
    ctx.assets = AssetPaths::from_environment();
    ExperimentOutput out = run_and_write(registry.get(name), ctx);
    for (const char* file : {"results.csv", "results.json", "table.md"})
        EXPECT_TRUE(fs::exists(ctx.output_dir / file)) << name << ": " << file;
    if (plotting_available()) {
        for (const auto& [plot_name, plot] : out.plots)
            EXPECT_TRUE(fs::exists(ctx.output_dir / (plot_name + ".svg"))) << plot_name;
    }
    EXPECT_FALSE(out.tables.empty());
    for (const ResultTable& t : out.tables) {
        EXPECT_FALSE(t.rows.empty()) << t.title;
        for (const nlohmann::json& row : t.rows)
            for (const std::string& c : t.columns) EXPECT_TRUE(row.contains(c)) << t.title << ": " << c;
    }
    return out;
}

}  // namespace gilab::test
