// gilab.experiments(), gilab.experiment_plan() and gilab.run_experiment(): the experiment registry and runner of
// `gilab experiment`, with the result tables handed back as lists of dicts.
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <optional>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>
#include "core/util/error.hpp"
#include "core/util/parallel.hpp"
#include "experiments/runner/experiment.hpp"
#include "experiments/runner/experiment_batch.hpp"
#include "experiments/runner/spec_runner.hpp"
#include "experiments/runner/task_command.hpp"
#include "python/array_helpers.hpp"
#include "python/bindings.hpp"

namespace gilab::python {

using namespace pybind11::literals;
namespace fs = std::filesystem;

namespace {

// A private directory for a run whose files nobody asked for; removed afterwards.
class TemporaryDirectory {
public:
    TemporaryDirectory() {
        std::string pattern = (fs::temp_directory_path() / "gilab-experiment-XXXXXX").string();
        if (!mkdtemp(pattern.data())) throw Error(pattern, "cannot create a temporary directory");
        path_ = pattern;
    }
    ~TemporaryDirectory() {
        std::error_code ec;
        fs::remove_all(path_, ec);
    }
    TemporaryDirectory(const TemporaryDirectory&) = delete;
    TemporaryDirectory& operator=(const TemporaryDirectory&) = delete;
    const fs::path& path() const { return path_; }

private:
    fs::path path_;
};

// Runs one experiment as `gilab experiment` does: into a hidden staging folder under the
// results root, published as RESULTS/NAME in one rename when every file is written.
ExperimentOutput run_into(const Experiment& experiment, const fs::path& results_root, ExperimentContext context) {
    fs::create_directories(results_root);
    const fs::path staging = staging_directory(results_root, experiment.name);
    std::error_code ec;
    fs::remove_all(staging, ec);  // left by an interrupted run
    context.output_dir = staging;
    try {
        ExperimentOutput output = run_and_write(experiment, context);
        publish_directory(staging, results_root / experiment.name);
        return output;
    } catch (...) {
        fs::remove_all(staging, ec);
        throw;
    }
}

py::dict output_to_python(const Experiment& experiment, const ExperimentOutput& output,
                          const std::optional<fs::path>& directory) {
    py::list tables;
    for (const ResultTable& t : output.tables) {
        py::list rows;
        for (const nlohmann::json& row : t.rows) rows.append(json_to_python(row));
        tables.append(py::dict("title"_a = t.title, "columns"_a = t.columns, "rows"_a = rows));
    }
    return py::dict("name"_a = experiment.name, "paper"_a = experiment.paper, "tables"_a = tables,
                    "config"_a = json_to_python(output.config), "notes"_a = output.notes, "files"_a = output.files,
                    "directory"_a = directory ? py::cast(directory->string()) : py::none());
}

// A registered experiment by name, or one declared here as a dict (the spec's JSON form,
// as results.json's "config" shows it); its probes and reducers are the registered ones.
Experiment experiment_from(const py::object& name_or_spec) {
    if (py::isinstance<py::str>(name_or_spec))
        return ExperimentRegistry::builtin().get(name_or_spec.cast<std::string>());  // lists the names when unknown
    if (!py::isinstance<py::dict>(name_or_spec))
        throw Error("experiment", "expected a name or a spec dict, not " + py::str(py::type::of(name_or_spec)).cast<std::string>());
    (void)ExperimentRegistry::builtin();  // registers the probes and reducers a spec may name
    return declared_experiment(ExperimentSpec::from_json(python_to_json(name_or_spec, "experiment spec")));
}

}  // namespace

void register_experiment_bindings(py::module_& m) {
    m.def(
        "experiments",
        [] {
            py::list list;
            for (const Experiment& e : ExperimentRegistry::builtin().list())
                list.append(py::dict("name"_a = e.name, "paper"_a = e.paper, "description"_a = e.description));
            return list;
        },
        "The registered experiments as dicts (name, paper, description), as `gilab experiment list`.");

    m.def(
        "experiment_plan",
        [](const py::object& name_or_spec, bool quick) {
            const Experiment experiment = py::isinstance<py::str>(name_or_spec)
                                              ? declared_experiment_named(name_or_spec.cast<std::string>())
                                              : experiment_from(name_or_spec);
            py::list tasks;
            for (const SpecTask& t : plan_tasks(*experiment.spec, quick))
                tasks.append(json_to_python(plan_entry(*experiment.spec, t, quick)));
            return tasks;
        },
        "experiment"_a, "quick"_a = true,
        "The tasks of a declared experiment — a name, or a spec dict as run_experiment takes — as dicts (id, scene, "
        "axes, variants with their technique or probe and settings, and the reference group as 'references' when "
        "the task compares against path-traced references), as `gilab experiment plan NAME --quick` "
        "(quick=False: the full plan, as without --quick).");

    m.def(
        "run_experiment",
        [](const py::object& name_or_spec, bool quick, const std::optional<fs::path>& results, uint64_t seed,
           int threads, bool verbose, const py::object& assets) {
            if (threads < 0 || threads > 1024)
                throw Error("threads", std::to_string(threads) + " is not a thread count (0 = all cores, or 1 to 1024)");
            const Experiment experiment = experiment_from(name_or_spec);
            ExperimentContext context;
            context.quick = quick;
            context.seed = seed;
            context.threads = threads;
            context.log = verbose ? &std::cerr : nullptr;
            context.assets = AssetPaths::from_environment(
                assets.is_none() ? std::nullopt : std::optional(py::str(assets).cast<std::string>()));
            ExperimentOutput output;
            {
                py::gil_scoped_release release;
                ThreadLimit limit(threads);
                if (results) {
                    output = run_into(experiment, *results, context);
                } else {
                    TemporaryDirectory scratch;
                    output = run_into(experiment, scratch.path(), context);
                }
            }
            return output_to_python(experiment, output,
                                    results ? std::optional(*results / experiment.name) : std::nullopt);
        },
        "experiment"_a, "quick"_a = true, "results"_a = py::none(), "seed"_a = 1, "threads"_a = 0, "verbose"_a = false,
        "assets"_a = py::none(), R"doc(Runs one experiment as ``gilab experiment NAME`` does and returns its result
as a dict. The experiment is a name (see gilab.experiments()) or a spec declared here
as a dict, in the form results.json's "config" shows, for example

    gilab.run_experiment({
        "name": "my-radius-sweep", "scenes": ["cornell"],
        "size": {"full": 256, "quick": 32}, "frames": 1,
        "variants": [{"name": "hash grid", "technique": "photon",
                      "settings": {"photon_map": "hash_grid"}}],
        "axes": [{"setting": "radius", "values": [0.05, 0.1]}],
        "measures": [{"column": "frame_ms", "key": "render_ms"},
                     {"column": "photons_stored", "key": "photons_stored",
                      "source": "prepare stat"}]})

(sources: "frame stat (median over frames)", "prepare stat", "last frame's stat",
"relMSE against the path-traced reference", "last frame's layer mean", "last frame's
layer digest"; a variant may name a registered "probe" instead of a technique, and the
spec a registered "reducer"). The result:

    {"name", "paper", "tables": [{"title", "columns", "rows": [dict, …]}, …],
     "config", "notes", "files", "directory"}

quick     small sizes (a smoke run)
results   results root: writes RESULTS/NAME/ (results.csv, results.json,
          table.md, plots) atomically; None runs in a temporary directory that is
          removed afterwards ("directory" is then None)
seed, threads   as --seed and --threads (0 = all cores)
verbose   progress messages on stderr

The GIL is released while it runs. Unknown names raise gilab.Error listing them.
)doc");
}

}  // namespace gilab::python
