#pragma once
// What the P2 experiments on voxelized models share: the models (a Stanford model without
// its floor, or a whole scene) as placed by their scene files, loaded once per run; the
// probe wrapper that skips a model whose assets are missing with a note; the grid around
// a model; and the helpers their tables and memory guards use.
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>
#include <nlohmann/json.hpp>
#include "core/scene/scene.hpp"
#include "core/voxel/voxel_grid.hpp"
#include "experiments/runner/spec_functions.hpp"

namespace gilab::p2 {

// A model: `scene` is the spec's scene name, `node` names the scene file's entry to
// voxelize (every mesh under it; a floor is another entry and is left out), `paper` its
// name in P2's tables ("" for the models the paper does not have).
struct ModelSpec {
    std::string label;
    std::string scene;
    std::string node;
    std::string paper;
};

// P2's three models in its table order, then the whole scenes.
const std::vector<ModelSpec>& model_specs();
const ModelSpec& model_spec(const std::string& scene);  // throws Error naming the known scenes
// The scene names of the paper's three models, in its order.
std::vector<std::string> paper_model_scenes();
// The scene names of every model, in model_specs' order.
std::vector<std::string> model_scenes();

struct Model {
    std::string label, scene, paper;
    std::vector<Vec3> positions;
    std::vector<UVec3> triangles;
    Bounds3 bounds;
    SceneCamera camera;
};

// The model's meshes in world space (as placed by its scene file).
std::shared_ptr<const Model> load_model(const ModelSpec& spec, const AssetPaths& assets);

// A model, or why it could not be loaded (a missing asset skips its rows with a note).
struct ModelLoad {
    std::shared_ptr<const Model> model;
    std::string skipped;
};

// The task's model, loaded once per run and shared by its tasks.
const ModelLoad& task_model(const ProbeCall& call);

// A probe over a loaded model: `measure` fills the output; a model that did not load
// gives no rows and the note saying why.
template <class Measure>
ProbeFunction model_probe(Measure measure) {
    return [measure](const ProbeCall& call) {
        const ModelLoad& load = task_model(call);
        ProbeOutput out;
        if (!load.model) {
            out.notes.push_back(load.skipped);
            return out;
        }
        measure(call, *load.model, out);
        return out;
    };
}

// The smallest cube around the model, grown by 0.1% per side (VoxelGrid::enclosing).
VoxelGrid model_grid(const Model& model, uint32_t res);

// How the P2 tables place the paper's models in their grids.
extern const char* const kGridNote;

std::string cube(uint32_t n);  // "512³"

// MemAvailable from /proc/meminfo (8 GiB when unreadable): memory guards take half.
size_t available_memory_bytes();
std::string budget_text(uint64_t need, size_t budget);  // "about N MiB needed, budget M MiB"

// `row` with exactly `columns`, in that order (null where it has none).
nlohmann::json project(const nlohmann::json& row, const std::vector<std::string>& columns);
// Every row of every task whose "kind" is `kind` (all rows when empty), in plan order.
std::vector<nlohmann::json> rows_of(const SpecReduction& r, const std::string& kind = "");
// The machine's load over the tasks that timed something (rows with load averages).
std::optional<std::string> load_note(const std::vector<nlohmann::json>& rows);
// Means of `columns` over the rows present, per resolution and over all rows ("all"):
// columns resolution, rows (those with a number in columns[0]), mean_<column> each.
ResultTable resolution_means(const std::vector<nlohmann::json>& rows, const std::vector<nlohmann::json>& resolutions,
                             const std::vector<std::string>& columns);
// The resolutions of the plan that ran (quick or full): a scale experiment's first axis.
const std::vector<nlohmann::json>& plan_resolutions(const SpecReduction& r);
// A scale experiment's tables: `rows` projected onto `columns` under `title`, then the
// resolution_means of `mean_columns` over plan_resolutions.
std::vector<ResultTable> scale_tables(const SpecReduction& r, const std::vector<nlohmann::json>& rows,
                                      std::string title, const std::vector<std::string>& columns,
                                      const std::vector<std::string>& mean_columns);

}  // namespace gilab::p2
