#include "scenes/scene_library.hpp"

#include <algorithm>
#include <filesystem>
#include "core/error.hpp"
#include "core/mesh_loaders.hpp"
#include "core/scene_file.hpp"
#include "scenes/builtin_scenes.hpp"

namespace gilab {

namespace fs = std::filesystem;

std::string scenes_directory() { return std::string(GILAB_SOURCE_DIR) + "/scenes"; }

std::vector<std::string> scene_file_names() {
    std::vector<std::string> names;
    std::error_code ec;
    for (const auto& entry : fs::directory_iterator(scenes_directory(), ec))
        if (entry.path().extension() == ".json") names.push_back(entry.path().stem().string());
    std::sort(names.begin(), names.end());
    return names;
}

SceneCamera default_camera_for(const Bounds3& bounds) {
    SceneCamera camera;
    Vec3 c = bounds.center();
    float radius = 0.5f * glm::length(bounds.extent());
    camera.vertical_fov_degrees = 45.0f;
    float distance = radius / std::tan(glm::radians(camera.vertical_fov_degrees) * 0.5f) * 1.1f;
    camera.target = c;
    camera.position = c + Vec3(0, 0.25f * radius, -distance);
    return camera;
}

namespace {

void add_defaults(Scene& scene, std::vector<std::string>& warnings) {
    if (!scene.has_emitters()) {
        PunctualLight sun;
        sun.name = "default_sun";
        sun.type = LightType::Directional;
        sun.direction = glm::normalize(Vec3(0.3f, -1.0f, 0.4f));
        sun.intensity = Vec3(3.0f);
        scene.lights.push_back(sun);
        warnings.push_back("scene has no lights: added a default directional sun");
    }
    if (!scene.camera) {
        SceneFrame frame = scene.evaluate(0.0);
        scene.camera = default_camera_for(frame.bounds);
        warnings.push_back("scene has no camera: framing its bounds");
    }
}

}  // namespace

OpenedScene open_scene(const std::string& spec, const AssetPaths& assets) {
    OpenedScene opened;
    for (const auto& builtin : builtin_scenes())
        if (builtin.name == spec) {
            opened.scene = builtin.make();
            return opened;
        }
    fs::path path(spec);
    fs::path shipped = fs::path(scenes_directory()) / (spec + ".json");
    if (!path.has_extension() && fs::exists(shipped)) path = shipped;
    if (!path.has_extension()) {
        std::string known;
        for (const auto& b : builtin_scenes()) known += (known.empty() ? "" : ", ") + b.name;
        for (const auto& n : scene_file_names()) known += ", " + n;
        throw Error(spec, "unknown scene (known: " + known + "; or give a path to a .json/.obj/.gltf/.glb/.ply/.off file)");
    }
    std::string ext = path.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    if (ext == ".json") {
        if (!fs::exists(path)) throw Error(path.string(), "scene file not found");
        opened.scene = load_scene_file(path, assets);
    } else {
        fs::path resolved = fs::exists(path) ? path : assets.resolve(spec);
        opened.scene = load_mesh_file(resolved);
    }
    opened.warnings.insert(opened.warnings.end(), opened.scene.warnings.begin(), opened.scene.warnings.end());
    if (opened.scene.degenerate_triangles_dropped > 0)
        opened.warnings.push_back(std::to_string(opened.scene.degenerate_triangles_dropped) +
                                  " zero-area triangles dropped");
    opened.scene.validate();
    add_defaults(opened.scene, opened.warnings);
    return opened;
}

}  // namespace gilab
