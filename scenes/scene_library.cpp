#include "scenes/scene_library.hpp"

#include <algorithm>
#include <filesystem>
#include <sstream>
#include "core/util/build_info.hpp"
#include "core/util/error.hpp"
#include "core/io/mesh_loaders.hpp"
#include "core/io/scene_file.hpp"
#include "scenes/builtin_scenes.hpp"

namespace gilab {

namespace fs = std::filesystem;

std::string scenes_directory() { return std::string(build_source_directory()) + "/scenes"; }

std::vector<std::string> scene_file_names() {
    std::vector<std::string> names;
    std::error_code ec;
    for (const auto& entry : fs::directory_iterator(scenes_directory(), ec))
        if (entry.path().extension() == ".json") names.push_back(entry.path().stem().string());
    std::sort(names.begin(), names.end());
    return names;
}

namespace {

// Geometry thinner than this fraction of its largest extent counts as flat, and a view
// that sees less than this fraction of the surface area face-on counts as edge-on.
constexpr float kFlat = 0.01f;
constexpr double kEdgeOn = 0.05;

// The sun added to scenes without lights travels down and away from the −Z side, so
// the default camera looks at a flat model from the side this sun lights.
Vec3 default_sun_direction() { return glm::normalize(Vec3(0.3f, -1.0f, 0.4f)); }

// Looking at the bounds' centre from direction `from` (centre → camera), far enough
// back for the bounding sphere to fill the vertical field of view.
float framing_distance(const Bounds3& bounds, float vertical_fov_degrees) {
    const float radius = 0.5f * glm::length(bounds.extent());
    return radius / std::tan(glm::radians(vertical_fov_degrees) * 0.5f) * 1.1f;
}

SceneCamera camera_from(const Bounds3& bounds, const Vec3& from) {
    SceneCamera camera;
    camera.vertical_fov_degrees = 45.0f;
    const float distance = framing_distance(bounds, camera.vertical_fov_degrees);
    camera.target = bounds.center();
    camera.position = camera.target + glm::normalize(from) * (distance > 0 ? distance : 1.0f);
    camera.up = std::abs(glm::normalize(from).y) > 0.9f ? Vec3(0, 0, -1) : Vec3(0, 1, 0);
    return camera;
}

// Share of the surface area that faces `view` (area-weighted |cos|), with the
// area-weighted normal covariance for finding a better direction.
struct Facing {
    double seen = 0, total = 0;
    glm::dmat3 covariance{0.0};
};

Facing facing(const SceneFrame& frame, const Vec3& view) {
    Facing f;
    const DVec3 v = glm::normalize(DVec3(view));
    for (const WorldMesh& m : frame.meshes)
        for (const UVec3& t : m.triangles) {
            const DVec3 a(m.positions[t.x]), b(m.positions[t.y]), c(m.positions[t.z]);
            const DVec3 n2 = glm::cross(b - a, c - a);
            const double area = 0.5 * glm::length(n2);
            if (!(area > 0)) continue;
            const DVec3 n = n2 / (2 * area);
            f.total += area;
            f.seen += area * std::abs(glm::dot(n, v));
            f.covariance += area * glm::outerProduct(n, n);
        }
    return f;
}

}  // namespace

SceneCamera default_camera_for(const Bounds3& bounds) {
    const Vec3 e = bounds.extent();
    const float largest = max_component(e);
    const int thin = e.x <= e.y && e.x <= e.z ? 0 : e.y <= e.z ? 1 : 2;
    if (largest > 0 && e[thin] <= kFlat * largest) {
        // Flat: look along the thin axis so the geometry is seen face-on, never edge-on,
        // from the side the default sun lights.
        Vec3 from(0);
        from[thin] = -default_sun_direction()[thin] >= 0 ? 1.0f : -1.0f;
        return camera_from(bounds, from);
    }
    // From the front (−Z side), a little above.
    SceneCamera camera;
    camera.vertical_fov_degrees = 45.0f;
    camera.target = bounds.center();
    camera.position = camera.target + Vec3(0, 0.25f * 0.5f * glm::length(e), -framing_distance(bounds, camera.vertical_fov_degrees));
    return camera;
}

SceneCamera default_camera_for(const SceneFrame& frame, bool* edge_on) {
    SceneCamera camera = default_camera_for(frame.bounds);
    Facing f = facing(frame, camera.target - camera.position);
    if (f.total > 0 && f.seen < kEdgeOn * f.total) {
        // Mostly edge-on (e.g. a tilted flat model): look along the direction most of the
        // surface faces, the dominant eigenvector of the normals' covariance, from the
        // side the default sun lights.
        DVec3 axis(1, 1, 1);
        for (int k = 0; k < 64; ++k) {
            const DVec3 next = f.covariance * axis;
            if (!(glm::length(next) > 0)) break;
            axis = glm::normalize(next);
        }
        if (glm::dot(axis, -DVec3(default_sun_direction())) < 0) axis = -axis;
        camera = camera_from(frame.bounds, Vec3(axis));
        f = facing(frame, camera.target - camera.position);
    }
    if (edge_on) *edge_on = f.total > 0 && f.seen < kEdgeOn * f.total;
    return camera;
}

namespace {

void add_defaults(Scene& scene, std::vector<std::string>& warnings, bool& default_camera) {
    default_camera = !scene.camera;
    if (!scene.has_emitters()) {
        PunctualLight sun;
        sun.name = "default_sun";
        sun.type = LightType::Directional;
        sun.direction = default_sun_direction();
        sun.intensity = Vec3(3.0f);
        scene.lights.push_back(sun);
        warnings.push_back("scene has no lights: added a default directional sun");
    }
    if (!scene.camera) {
        SceneFrame frame = scene.evaluate(0.0);
        bool edge_on = false;
        scene.camera = default_camera_for(frame, &edge_on);
        const Vec3 d = glm::normalize(scene.camera->target - scene.camera->position);
        std::ostringstream text;
        text << "scene has no camera: framing its bounds, looking along (" << d.x << ", " << d.y << ", " << d.z << ")";
        warnings.push_back(text.str());
        if (edge_on)
            warnings.push_back("the default camera sees the geometry almost edge-on from every direction tried; "
                               "give the scene a camera");
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
    add_defaults(opened.scene, opened.warnings, opened.default_camera);
    return opened;
}

}  // namespace gilab
