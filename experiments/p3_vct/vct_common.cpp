#include "experiments/p3_vct/vct_common.hpp"

#include <algorithm>
#include <map>
#include "core/image/image_io.hpp"
#include "core/util/error.hpp"
#include "core/util/format.hpp"
#include "core/util/settings.hpp"
#include "scenes/builtin_scenes.hpp"
#include "scenes/scene_library.hpp"

namespace gilab::vct {

namespace {

// The Cornell box holding a Stanford model, fitted to half the box's width and standing
// on its floor. The model keeps its own material.
Scene cornell_with(const ExperimentContext& ctx, const std::string& model) {
    Scene source = open_scene(model, ctx.assets).scene;
    SceneFrame frame = source.evaluate(0);
    // The model is the scene's largest mesh (the rest is the floor).
    const WorldMesh* mesh = nullptr;
    for (const WorldMesh& m : frame.meshes)
        if (!mesh || m.triangles.size() > mesh->triangles.size()) mesh = &m;
    if (!mesh || mesh->triangles.empty()) throw Error("vct experiments", "scene '" + model + "' has no mesh");
    Bounds3 b;
    for (const Vec3& p : mesh->positions) b.extend(p);
    const Vec3 e = b.extent();
    const float scale = 0.5f / std::max(e.x, std::max(e.y, e.z));
    Scene scene = make_cornell_box();
    scene.name = "cornell+" + model;
    const uint32_t material = uint32_t(scene.materials.size());
    scene.materials.push_back(source.materials.at(mesh->material_ids.empty() ? 0 : mesh->material_ids[0]));
    Mesh m;
    m.name = model;
    const Vec3 floor_centre(0.5f, 0.0f, 0.5f);
    for (const Vec3& p : mesh->positions)
        m.positions.push_back(floor_centre + scale * (p - Vec3(b.center().x, b.min.y, b.center().z)));
    m.triangles = mesh->triangles;
    m.material_ids.assign(m.triangles.size(), material);
    scene.add_mesh_instance(std::move(m));
    return scene;
}

// Two closed rooms side by side sharing a wall thinner than a voxel; a point light in
// room A, the camera in room B. Light reaching room B through the wall is leaked.
Scene thin_wall_scene(float wall) {
    Scene scene;
    scene.name = "thin_wall";
    scene.source = "builtin:thin_wall";
    Material white;
    white.albedo = Vec3(0.7f);
    scene.materials = {white};
    Mesh m;
    m.name = "rooms";
    auto quad = [&](Vec3 a, Vec3 b, Vec3 c, Vec3 d) {
        uint32_t base = uint32_t(m.positions.size());
        m.positions.insert(m.positions.end(), {a, b, c, d});
        m.triangles.push_back({base, base + 1, base + 2});
        m.triangles.push_back({base, base + 2, base + 3});
        m.material_ids.insert(m.material_ids.end(), {0, 0});
    };
    auto box = [&](Vec3 lo, Vec3 hi) {  // six faces of an axis-aligned box
        quad({lo.x, lo.y, lo.z}, {hi.x, lo.y, lo.z}, {hi.x, lo.y, hi.z}, {lo.x, lo.y, hi.z});
        quad({lo.x, hi.y, lo.z}, {lo.x, hi.y, hi.z}, {hi.x, hi.y, hi.z}, {hi.x, hi.y, lo.z});
        quad({lo.x, lo.y, lo.z}, {lo.x, hi.y, lo.z}, {hi.x, hi.y, lo.z}, {hi.x, lo.y, lo.z});
        quad({lo.x, lo.y, hi.z}, {hi.x, lo.y, hi.z}, {hi.x, hi.y, hi.z}, {lo.x, hi.y, hi.z});
        quad({lo.x, lo.y, lo.z}, {lo.x, lo.y, hi.z}, {lo.x, hi.y, hi.z}, {lo.x, hi.y, lo.z});
        quad({hi.x, lo.y, lo.z}, {hi.x, hi.y, lo.z}, {hi.x, hi.y, hi.z}, {hi.x, lo.y, hi.z});
    };
    box(Vec3(0, 0, 0), Vec3(4, 1, 1));                               // the outer shell
    box(Vec3(2 - 0.5f * wall, 0, 0), Vec3(2 + 0.5f * wall, 1, 1));  // the partition
    scene.add_mesh_instance(std::move(m));
    PunctualLight light;
    light.name = "lamp";
    light.position = Vec3(1.0f, 0.8f, 0.5f);
    light.intensity = Vec3(2.0f);
    scene.lights.push_back(light);
    SceneCamera cam;
    cam.position = Vec3(3.8f, 0.5f, 0.5f);
    cam.target = Vec3(2.0f, 0.35f, 0.5f);
    cam.vertical_fov_degrees = 70;
    scene.camera = cam;
    return scene;
}

// Sponza with the scene camera; the stone made slightly glossy so the specular cone has
// something to do (the scene file has one diffuse material).
Scene glossy_sponza(const ExperimentContext& ctx) {
    Scene scene = open_scene("sponza", ctx.assets).scene;
    for (Material& m : scene.materials) {
        m.specular = Vec3(0.15f);
        m.phong_exponent = 60.0f;
    }
    return scene;
}

}  // namespace

const Scene& scene_named(const ProbeCall& call, const std::string& name) {
    if (name == "thin_wall") {
        const float wall = call.setting<float>("wall_thickness");
        return call.cache.get<Scene>("vct scene:thin_wall " + std::to_string(wall), [&] { return thin_wall_scene(wall); });
    }
    return call.cache.get<Scene>("vct scene:" + name, [&] {
        if (name.starts_with("cornell+")) return cornell_with(call.ctx, name.substr(8));
        if (name == "sponza, glossy") return glossy_sponza(call.ctx);
        return open_scene(name, call.ctx.assets).scene;
    });
}

const Scene* scene_or_skip(const ProbeCall& call, const std::string& name, ProbeOutput& out) {
    try {
        return &scene_named(call, name);
    } catch (const Error& e) {
        out.notes.push_back(skip_note(call.ctx, name, e.what()));
        return nullptr;
    }
}

const Scene* loadable_scene(const ProbeCall& call, const std::string& name) {
    try {
        return &scene_named(call, name);
    } catch (const Error&) {
        return nullptr;
    }
}

std::string scene_of(const ProbeCall& call) { return call.setting<std::string>("scene", call.task.scene); }

EyeCamera scene_camera(const Scene& scene, int size) {
    const SceneCamera& c = *scene.camera;
    return EyeCamera::look_at(c.position, c.target, c.up, c.vertical_fov_degrees, size, size);
}

const std::vector<CameraWalk>& camera_walks() {
    static const std::vector<CameraWalk> w = {
        {"sponza", {-10.0f, 2.0f, 0.3f}, {8.0f, 2.0f, 0.3f}, {6.0f, 1.2f, 0.0f}, "eye from (−10, 2, 0.3) to (8, 2, 0.3), looking +x"},
        {"sibenik", {14.0f, -10.5f, 0.0f}, {-6.0f, -10.5f, 0.0f}, {-6.0f, 0.8f, 0.0f},
         "eye from (14, −10.5, 0) to (−6, −10.5, 0), 2 m above the nave floor, looking −x towards the apse"}};
    return w;
}

const CameraWalk& camera_walk(const std::string& scene) {
    for (const CameraWalk& w : camera_walks())
        if (w.scene == scene) return w;
    throw Error("vct experiments", "no camera walk through '" + scene + "'");
}

std::vector<EyeCamera> walk_cameras(const CameraWalk& walk, int size, int frames) {
    std::vector<EyeCamera> cams;
    for (int i = 0; i < frames; ++i) {
        const float t = frames > 1 ? float(i) / float(frames - 1) : 0.0f;
        const Vec3 eye = walk.from + t * (walk.to - walk.from);
        cams.push_back(EyeCamera::look_at(eye, eye + walk.look, Vec3(0, 1, 0), 60.0f, size, size));
    }
    return cams;
}

Vec3 scene_viewer(const Scene& scene) {
    const Bounds3 b = scene.evaluate(0).bounds;
    if (scene.camera && b.contains(scene.camera->position)) return scene.camera->position;
    return b.center();
}

nlohmann::json vct_settings(const ProbeCall& call) {
    nlohmann::json settings = call.setting<nlohmann::json>("vct", nlohmann::json::object());
    if (!settings.contains("dense_resolution") && call.variant.settings.contains("dense_resolution"))
        settings["dense_resolution"] = call.variant.settings.at("dense_resolution");
    return settings;
}

std::unique_ptr<Technique> make_vct(const Scene& scene, nlohmann::json settings, const ExperimentContext& ctx) {
    settings["seed"] = ctx.seed;
    if (ctx.quick && !settings.contains("injection_cones")) settings["injection_cones"] = kQuickInjectionCones;
    return prepare_technique("vct", scene, Settings(settings, "vct experiment settings"));
}

Film render(Technique& t, const EyeCamera& camera) {
    std::vector<Film> films;
    t.render(ViewSet::mono(camera), films);
    return films.at(0);
}

void save_images(const ExperimentContext& ctx, std::vector<std::string>& files, const std::string& name, const Film& film) {
    write_exr(ctx.output_dir / (name + ".exr"), film);
    write_png(ctx.output_dir / (name + ".png"), film);
    files.push_back(name + ".exr");
    files.push_back(name + ".png");
}

std::string skip_note(const ExperimentContext& ctx, const std::string& scene, const std::string& why) {
    ctx.say("skipping " + scene + ": " + why);
    return "scene '" + scene + "' skipped: " + why;
}

namespace {

std::string value_text(const nlohmann::json& v) { return v.is_string() ? v.get<std::string>() : v.dump(); }

// Each setting of the axis with its values in plan order (an axis of objects gives
// every key of its objects).
std::vector<std::pair<std::string, std::vector<std::string>>> axis_values(const SpecAxis& axis,
                                                                          const std::vector<nlohmann::json>& values) {
    std::vector<std::pair<std::string, std::vector<std::string>>> out;
    auto add = [&](const std::string& key, const nlohmann::json& v) {
        auto it = std::find_if(out.begin(), out.end(), [&](const auto& kv) { return kv.first == key; });
        if (it == out.end()) it = out.insert(out.end(), {key, {}});
        it->second.push_back(value_text(v));
    };
    for (const nlohmann::json& v : values) {
        if (!axis.setting.empty()) add(axis.setting, v);
        else
            for (auto item = v.begin(); item != v.end(); ++item) add(item.key(), item.value());
    }
    return out;
}

}  // namespace

std::vector<std::string> quick_notes(const SpecReduction& r, QuickNoteParts parts) {
    if (!r.ctx.quick) return {};
    const ExperimentSpec& s = r.spec;
    std::vector<std::string> changes;
    bool dense_smaller = false;
    for (const SpecAxis& axis : s.axes) {
        const auto quick = axis_values(axis, axis.quick), full = axis_values(axis, axis.full);
        for (const auto& [key, values] : quick) {
            auto f = std::find_if(full.begin(), full.end(), [&](const auto& kv) { return kv.first == key; });
            if (f != full.end() && f->second == values) continue;
            std::string change = key + " " + join(values);
            if (f != full.end()) change += " (full: " + join(f->second) + ")";
            if (key == "dense_resolution") {
                change += " where the variant does not fix its own";
                dense_smaller = true;
            }
            changes.push_back(change);
        }
    }
    if (parts.images && s.quick_size != s.size)
        changes.push_back("images " + std::to_string(s.quick_size) + "² (full: " + std::to_string(s.size) + "²)");
    if (parts.frames && s.quick_frames != s.frames)
        changes.push_back(std::to_string(s.quick_frames) + " frames per task (full: " + std::to_string(s.frames) + ")");
    if (parts.reference_spp && s.quick_reference_spp != s.reference_spp)
        changes.push_back("reference " + std::to_string(s.quick_reference_spp) + " samples per pixel (full: " +
                          std::to_string(s.reference_spp) + ")");
    if (parts.cones) {
        const SettingsSchema& schema = TechniqueRegistry::builtin().find("vct")->settings_schema();
        changes.push_back(std::to_string(kQuickInjectionCones) + " voxel-bounce cones per side of a voxel (full: " +
                          schema.spec("injection_cones").default_text() + ")");
    }
    if (changes.empty()) return {};
    std::string note = "Quick run: " + join(changes) + ".";
    if (dense_smaller) note += " At this size the dense texture is small, so memory and time ratios favour it.";
    return {note};
}

void require_rows(const SpecReduction& r) {
    for (const TaskResult& t : r.tasks)
        if (!t.rows.empty()) return;
    throw Error(r.spec.name, "no scene could be loaded");
}

std::vector<nlohmann::json> all_rows(const SpecReduction& r) {
    std::vector<nlohmann::json> rows;
    for (const TaskResult& t : r.tasks) rows.insert(rows.end(), t.rows.begin(), t.rows.end());
    return rows;
}

}  // namespace gilab::vct
