#pragma once
// The named pieces a spec calls that are not a technique run: probes (a measurement per
// task — a structure build, a voxelizer timing, ray throughput, a camera walk with an
// update policy) and reducers (the tasks' rows turned into the published table layout,
// with ratio and paper columns). Each experiment file registers its own; a spec names
// them, so a spec declared as a dict (Python) can use them too.
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>
#include <nlohmann/json.hpp>
#include "core/util/error.hpp"
#include "experiments/runner/experiment.hpp"
#include "experiments/runner/experiment_spec.hpp"
#include "experiments/runner/path_reference.hpp"

namespace gilab {

struct Scene;

// Things a run computes once and its tasks share (a loaded scene, a voxelization): the
// one-command run keeps them for all tasks, `run-task` for its one task.
class TaskCache {
public:
    template <class T, class Make>
    const T& get(const std::string& key, Make make) {
        auto it = items_.find(key);
        if (it == items_.end()) it = items_.emplace(key, std::make_shared<T>(make())).first;
        return *std::static_pointer_cast<T>(it->second);
    }

private:
    std::map<std::string, std::shared_ptr<void>> items_;
};

// What a probe is given: its task and variant (settings with the point applied), the
// run's context and sizes, and the cache.
struct ProbeCall {
    const ExperimentSpec& spec;
    const SpecTask& task;
    const TaskVariant& variant;
    const ExperimentContext& ctx;
    int size = 0, frames = 0, reference_spp = 0;
    TaskCache& cache;
    const Scene& scene() const;  // the task's scene by its `gilab render` name, loaded once per run
    // The same, or null when it cannot be loaded (a shared asset not installed), saying
    // why in `why` when given.
    const Scene* scene_or_null(std::string* why = nullptr) const;
    // The setting `key` of the variant, or `fallback` when the variant does not give it.
    template <class T>
    T setting(const std::string& key, T fallback) const {
        return variant.settings.contains(key) ? variant.settings.at(key).get<T>() : fallback;
    }
    template <class T>
    T setting(const std::string& key) const;  // throws naming the spec, task and key when absent
};

// What a probe returns: rows (column → value; "variant" defaults to the variant's name),
// notes for the table (a skipped model, say) and files it wrote into ctx.output_dir.
struct ProbeOutput {
    std::vector<nlohmann::json> rows;
    std::vector<std::string> notes, files;
};
using ProbeFunction = std::function<ProbeOutput(const ProbeCall&)>;
// The path-traced references a probe's task compares against (none for a missing scene).
// A sweep renders them first, as tasks of their own (`gilab experiment references`), so
// the tasks that share one find it in the store; the probe gets its references from the
// same function, so the two cannot differ.
using ProbeReferences = std::function<std::vector<ReferenceView>(const ProbeCall&)>;
// Which tasks need the same references as this one, decided from the plan alone (the
// call's scene is not loaded: only its task, variant, sizes and settings): tasks with
// equal groups share them, "" needs none. Without one, each task is a group of its own.
using ProbeReferenceGroup = std::function<std::string(const ProbeCall&)>;

// One task's merged result.
struct TaskResult {
    SpecTask task;
    std::vector<nlohmann::json> rows;  // each with "variant"
    std::vector<std::string> notes, files;
    // The row of variant `name`, or null.
    const nlohmann::json* row(const std::string& variant) const;
};

// What a reducer is given: the spec, the run's context, and the results of the tasks that
// ran, in plan order (a partial merge lacks some).
struct SpecReduction {
    const ExperimentSpec& spec;
    const ExperimentContext& ctx;
    std::vector<TaskResult> tasks;
    // One row per task and variant: scene, axis columns, variant, then the measures (or
    // the probe's columns in their first order).
    ResultTable default_table() const;
    int size() const;    // the image side of this run (quick or full)
    int frames() const;  // frames per task of this run
    int reference_spp() const;
};
// Tables, notes, plots and files from the reduction; the runner adds the config.
using ReducerFunction = std::function<ExperimentOutput(const SpecReduction&)>;

void add_probe(const std::string& name, ProbeFunction probe, ProbeReferences references = {},
               ProbeReferenceGroup group = {});
void add_reducer(const std::string& name, ReducerFunction reducer);
const ProbeFunction* find_probe(const std::string& name);
const ProbeReferences* find_probe_references(const std::string& name);  // null: the probe needs none
const ProbeReferenceGroup* find_probe_reference_group(const std::string& name);  // null: none given
const ReducerFunction* find_reducer(const std::string& name);

template <class T>
T ProbeCall::setting(const std::string& key) const {
    if (!variant.settings.contains(key))
        throw Error(spec.name + " task " + std::to_string(task.id), "variant '" + variant.name +
                                                                       "' has no setting '" + key + "'");
    return variant.settings.at(key).get<T>();
}

}  // namespace gilab
