#include "experiments/p2_dag/dag_models.hpp"

#include <fstream>
#include "core/util/error.hpp"
#include "experiments/runner/measures.hpp"
#include "scenes/scene_library.hpp"

namespace gilab::p2 {

using nlohmann::json;

const std::vector<ModelSpec>& model_specs() {
    static const std::vector<ModelSpec> specs = {{"Bunny", "bunny", "bunny", "Bunny"},
                                                 {"Happy Buddha", "buddha", "buddha", "Buddha"},
                                                 {"Dragon", "dragon", "dragon", "Dragon"},
                                                 // The castle without its ground, as the models without floors.
                                                 {"Castle", "castle", "castle", ""},
                                                 // Each scene file's one entry: the whole scene.
                                                 {"Sponza", "sponza", "sponza", ""},
                                                 {"Sibenik", "sibenik", "sibenik", ""},
                                                 {"Conference", "conference", "conference", ""}};
    return specs;
}

const ModelSpec& model_spec(const std::string& scene) {
    std::string known;
    for (const ModelSpec& m : model_specs()) {
        if (m.scene == scene) return m;
        known += (known.empty() ? "" : ", ") + m.scene;
    }
    throw Error("P2 DAG experiments", "no model for scene '" + scene + "' (" + known + ")");
}

std::vector<std::string> paper_model_scenes() {
    std::vector<std::string> scenes;
    for (const ModelSpec& m : model_specs())
        if (!m.paper.empty()) scenes.push_back(m.scene);
    return scenes;
}

std::vector<std::string> model_scenes() {
    std::vector<std::string> scenes;
    for (const ModelSpec& m : model_specs()) scenes.push_back(m.scene);
    return scenes;
}

std::shared_ptr<const Model> load_model(const ModelSpec& spec, const AssetPaths& assets) {
    Scene scene = open_scene(spec.scene, assets).scene;
    SceneFrame frame = scene.evaluate(0.0);
    auto model = std::make_shared<Model>();
    model->label = spec.label;
    model->scene = spec.scene;
    model->paper = spec.paper;
    for (const WorldMesh& mesh : frame.meshes) {
        bool inside = false;
        for (int n = int(mesh.node); n >= 0 && !inside; n = scene.nodes[size_t(n)].parent)
            inside = scene.nodes[size_t(n)].name == spec.node;
        if (!inside) continue;
        const uint32_t base = uint32_t(model->positions.size());
        model->positions.insert(model->positions.end(), mesh.positions.begin(), mesh.positions.end());
        for (const UVec3& t : mesh.triangles) model->triangles.push_back(t + UVec3(base));
    }
    if (model->triangles.empty())
        throw Error(scene.source, "no mesh under a node named '" + spec.node + "' (the model to voxelize)");
    for (const Vec3& p : model->positions) model->bounds.extend(p);
    model->camera = scene.camera.value_or(default_camera_for(model->bounds));
    return model;
}

const ModelLoad& task_model(const ProbeCall& call) {
    return call.cache.get<ModelLoad>("p2-model:" + call.task.scene, [&] {
        const ModelSpec& spec = model_spec(call.task.scene);
        ModelLoad load;
        try {
            load.model = load_model(spec, call.ctx.assets);
            call.ctx.say(spec.label + ": " + std::to_string(load.model->triangles.size()) + " triangles");
        } catch (const std::exception& e) {
            load.skipped = spec.label + " (scene '" + spec.scene + "') skipped: " + e.what();
            call.ctx.say("skipping " + spec.label + ": " + e.what());
        }
        return load;
    });
}

VoxelGrid model_grid(const Model& model, uint32_t res) { return VoxelGrid::enclosing(model.bounds, res); }

const char* const kGridNote =
    "Grid placement: each model is voxelized alone (its floor left out) as placed by its scene file in scenes/, in the "
    "smallest cube enclosing its bounding box, centred on the box and grown by 0.1% per side (VoxelGrid::enclosing); "
    "the longest side of the box spans the N voxels, the octree has depth ceil(log2 N) (1024 cells per axis for "
    "N = 1000, cells beyond N−1 never occupied). Voxels are conservative surface voxels (triangle/box overlap), not "
    "solid. The paper does not say how it placed or scaled its models, so absolute counts differ; the ratio columns "
    "are the comparable figures.";

std::string cube(uint32_t n) { return std::to_string(n) + "³"; }

size_t available_memory_bytes() {
    std::ifstream meminfo("/proc/meminfo");
    std::string key;
    size_t kib = 0;
    while (meminfo >> key) {
        if (key == "MemAvailable:") {
            meminfo >> kib;
            return kib * 1024;
        }
        meminfo.ignore(1 << 10, '\n');
    }
    return size_t(8) << 30;
}

std::string budget_text(uint64_t need, size_t budget) {
    return "about " + std::to_string(need >> 20) + " MiB needed, budget " + std::to_string(budget >> 20) + " MiB";
}

json project(const json& row, const std::vector<std::string>& columns) {
    json out = json::object();
    for (const std::string& c : columns) out[c] = row.contains(c) ? row.at(c) : json(nullptr);
    return out;
}

std::vector<json> rows_of(const SpecReduction& r, const std::string& kind) {
    std::vector<json> rows;
    for (const TaskResult& t : r.tasks)
        for (const json& row : t.rows)
            if (kind.empty() || row.value("kind", std::string()) == kind) rows.push_back(row);
    return rows;
}

std::optional<std::string> load_note(const std::vector<json>& rows) {
    if (rows.empty() || !rows.front().contains("load_average_before")) return std::nullopt;
    return "Load average (1 min) at the start of the first timed row: " + rows.front()["load_average_before"].dump() +
           "; at the end of the last: " + rows.back()["load_average_after"].dump() + ".";
}

ResultTable resolution_means(const std::vector<json>& rows, const std::vector<json>& resolutions,
                             const std::vector<std::string>& columns) {
    ResultTable t;
    t.title = "Mean over the rows present, per resolution and over all rows";
    t.columns = {"resolution", "rows"};
    for (const std::string& c : columns) t.columns.push_back("mean_" + c);
    auto summarize = [&](const json& resolution) {
        auto values = [&](const std::string& column) {
            std::vector<double> v;
            for (const json& row : rows)
                if ((resolution == "all" || row.at("resolution") == resolution) && row.contains(column) &&
                    row.at(column).is_number())
                    v.push_back(row.at(column).get<double>());
            return v;
        };
        json out = {{"resolution", resolution}, {"rows", values(columns.at(0)).size()}};
        for (const std::string& c : columns) {
            const std::vector<double> v = values(c);
            out["mean_" + c] = v.empty() ? json(nullptr) : json(mean(v));
        }
        t.rows.push_back(std::move(out));
    };
    for (const json& resolution : resolutions) summarize(resolution);
    summarize("all");
    return t;
}

const std::vector<json>& plan_resolutions(const SpecReduction& r) {
    return r.ctx.quick ? r.spec.axes.at(0).quick : r.spec.axes.at(0).full;
}

std::vector<ResultTable> scale_tables(const SpecReduction& r, const std::vector<json>& rows, std::string title,
                                      const std::vector<std::string>& columns,
                                      const std::vector<std::string>& mean_columns) {
    ResultTable table;
    table.title = std::move(title);
    table.columns = columns;
    for (const json& row : rows) table.rows.push_back(project(row, table.columns));
    return {std::move(table), resolution_means(rows, plan_resolutions(r), mean_columns)};
}

}  // namespace gilab::p2
