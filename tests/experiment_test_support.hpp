#pragma once
// Running one experiment in quick mode from a test, with the checks every experiment
// must pass: its three files are written, each plot it declares is drawn (when gnuplot
// is there), and every row of every table holds every column.
#include <gtest/gtest.h>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <string>
#include "experiments/runner/experiment.hpp"
#include "experiments/runner/plot.hpp"
#include "experiments/runner/spec_runner.hpp"
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

// Every experiment's quick tables keep the shape they had before experiments became
// declared specs: the same tables, columns and row keys (tests/experiments/
// quick_table_shapes.json, written from the hand-coded experiments' quick runs).
inline void expect_quick_shape(const std::string& name, const ExperimentOutput& out) {
    static const nlohmann::json shapes = [] {
        std::ifstream in(std::string(GILAB_SOURCE_DIR) + "/tests/experiments/quick_table_shapes.json");
        return nlohmann::json::parse(in);
    }();
    ASSERT_TRUE(shapes.contains(name)) << name << " has no recorded shape in quick_table_shapes.json";
    const nlohmann::json& tables = shapes.at(name);
    ASSERT_EQ(out.tables.size(), tables.size()) << name;
    for (size_t t = 0; t < tables.size(); ++t) {
        const ResultTable& table = out.tables[t];
        EXPECT_EQ(nlohmann::json(table.columns), tables[t].at("columns")) << name << " table " << t;
        nlohmann::json keys = nlohmann::json::array();
        for (const nlohmann::json& row : table.rows) {
            nlohmann::json key = nlohmann::json::array();
            for (const nlohmann::json& column : tables[t].at("key_columns"))
                key.push_back(row.value(column.get<std::string>(), nlohmann::json()));
            keys.push_back(key);
        }
        EXPECT_EQ(keys, tables[t].at("row_keys")) << name << " table " << t << " (" << table.title << ")";
    }
}

// A declared experiment's tables come from its task files alone: merging them again
// gives the same tables.
inline void expect_merge_reproduces(const Experiment& experiment, const ExperimentContext& ctx,
                                    const ExperimentOutput& out) {
    if (!experiment.spec) return;
    const ExperimentOutput merged = merge_spec_tasks(*experiment.spec, ctx);
    ASSERT_EQ(merged.tables.size(), out.tables.size()) << experiment.name;
    for (size_t t = 0; t < out.tables.size(); ++t) {
        EXPECT_EQ(merged.tables[t].columns, out.tables[t].columns) << experiment.name;
        EXPECT_EQ(nlohmann::json(merged.tables[t].rows), nlohmann::json(out.tables[t].rows)) << experiment.name;
    }
}

// Runs `experiment` quick into `ctx.output_dir` with the checks above.
inline ExperimentOutput run_quick_checked(const Experiment& experiment, const ExperimentContext& ctx) {
    ExperimentOutput out = run_and_write(experiment, ctx);
    expect_quick_shape(experiment.name, out);
    expect_merge_reproduces(experiment, ctx, out);
    return out;
}

// `written`, when given, receives the folder the run wrote.
inline ExperimentOutput run_quick_experiment(const ExperimentRegistry& registry, const std::string& name,
                                             std::filesystem::path* written = nullptr) {
    namespace fs = std::filesystem;
    ExperimentContext ctx;
    ctx.quick = true;
    ctx.output_dir = temp_dir("quick_experiment_" + name);
    if (written) *written = ctx.output_dir;
    ctx.assets = AssetPaths::from_environment();
    ExperimentOutput out = run_quick_checked(registry.get(name), ctx);
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
