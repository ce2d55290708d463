#pragma once
// An experiment reproduces one table or figure: it runs the code, returns tables of our
// figures (with the paper's published figures in clearly labelled "paper ..." columns),
// and the runner writes them to results/NAME/ atomically.
#include <filesystem>
#include <functional>
#include <memory>
#include <ostream>
#include <string>
#include <utility>
#include <vector>
#include <nlohmann/json.hpp>
#include "core/io/asset_paths.hpp"
#include "experiments/runner/experiment_spec.hpp"
#include "experiments/runner/plot.hpp"

namespace gilab {

struct ExperimentContext {
    bool quick = false;                       // small sizes for smoke runs
    std::filesystem::path output_dir;         // results/NAME (created by the runner)
    AssetPaths assets;
    uint64_t seed = 1;
    int threads = 0;                          // 0 = all cores
    std::ostream* log = nullptr;              // progress messages (may be null)
    void say(const std::string& message) const;
};

// One table. Rows are JSON objects keyed by column name. Columns whose name starts with
// "paper" hold the published figures (reference data), everything else is measured.
struct ResultTable {
    std::string title;
    std::vector<std::string> columns;
    std::vector<nlohmann::json> rows;
};

struct ExperimentOutput {
    std::vector<ResultTable> tables;     // tables[0] goes to results.csv
    nlohmann::json config = nlohmann::json::object();  // effective configuration
    std::vector<std::string> notes;      // printed under the tables in table.md
    std::vector<std::string> files;      // extra outputs written (images), relative names
    // Figures as (name, plot): the runner draws each as NAME.svg, adds it to files and
    // shows it in table.md.
    std::vector<std::pair<std::string, Plot>> plots;
};

struct Experiment {
    Experiment() = default;
    Experiment(std::string name, std::string paper, std::string description,
               std::function<ExperimentOutput(const ExperimentContext&)> run,
               std::shared_ptr<const ExperimentSpec> spec = nullptr)
        : name(std::move(name)), paper(std::move(paper)), description(std::move(description)), run(std::move(run)),
          spec(std::move(spec)) {}

    std::string name;          // e.g. "core-rays", "pm-table1"
    std::string paper;         // "P1", "P2", "P3" or "core"
    std::string description;
    std::function<ExperimentOutput(const ExperimentContext&)> run;
    // Set for an experiment declared as data: `gilab experiment plan | run-task | merge`
    // work on it, and `run` is the generic runner's (declared_experiment).
    std::shared_ptr<const ExperimentSpec> spec;
};

// An Experiment run by the generic runner from its spec (spec_runner.hpp); the spec is
// checked here, so a bad one fails at registration.
Experiment declared_experiment(ExperimentSpec spec);

class ExperimentRegistry {
public:
    void add(Experiment experiment);
    const Experiment* find(const std::string& name) const;
    const Experiment& get(const std::string& name) const;  // throws Error listing names
    const std::vector<Experiment>& list() const { return experiments_; }
    static const ExperimentRegistry& builtin();  // registered in experiments/runner/registry.cpp

private:
    std::vector<Experiment> experiments_;
};

// Runs the experiment and writes results.csv, results.json (figures, configuration, git
// revision, seed, machine), table.md and one SVG per plot into context.output_dir.
// A plot that cannot be drawn (no gnuplot) becomes a note instead of failing the run.
// Returns the output.
ExperimentOutput run_and_write(const Experiment& experiment, ExperimentContext context);

// Registration functions, one per paper/module (called from registry.cpp only).
void register_core_experiments(ExperimentRegistry& registry);
void register_photon_experiments(ExperimentRegistry& registry);    // P1: pm-table1..4, pm-fig8
void register_stereo_experiments(ExperimentRegistry& registry);    // P1: pm-table5, pm-final, pm-foveated
void register_dag_experiments(ExperimentRegistry& registry);       // P2: dag-table1..3, dag-fig13, dag-scale
void register_shadow_dag_experiments(ExperimentRegistry& registry);  // P2: dag-table4, dag-fig15, dag-fig16-18
void register_dynamic_dag_experiments(ExperimentRegistry& registry);  // P2: dag-table5, dag-table6
void register_vct_experiments(ExperimentRegistry& registry);       // P3: vct-table1..7, vct-fig9..13, vct-stability

}  // namespace gilab
