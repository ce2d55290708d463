// The gilab scene description (.json); the format is described in scenes/README.md.
// Every value is checked as it is read, and every key must be known: a misspelt key is
// an error naming its JSON path, never silently ignored.
#include "core/io/scene_file.hpp"

#include <fstream>
#include <map>
#include <set>
#include <nlohmann/json.hpp>
#include <sstream>
#include "core/util/error.hpp"
#include "core/util/format.hpp"
#include "core/util/input_file.hpp"
#include "core/util/json_document.hpp"
#include "core/io/mesh_loaders.hpp"
#include "core/scene/skin.hpp"

namespace gilab {

namespace fs = std::filesystem;
using json = nlohmann::json;

namespace {

// Faster than any display or capture rate; a larger value is a typo (1e12 frames per
// second would overflow the frame count).
constexpr double kMaxFramesPerSecond = 1000;

std::string type_name(const json& v) {
    if (v.is_number()) return "number";
    return v.type_name();
}

std::string join(const std::vector<std::string>& items) {
    std::string s;
    for (const auto& i : items) s += (s.empty() ? "" : ", ") + i;
    return s;
}

// Reads values out of the document; every failure names the file and the JSON path.
class Reader {
public:
    explicit Reader(std::string file) : file_(std::move(file)) {}

    [[noreturn]] void fail(const std::string& ptr, const std::string& message) const {
        throw Error(file_, (ptr.empty() ? std::string("/") : ptr) + ": " + message);
    }

    void check_object(const json& v, const std::string& ptr, const std::vector<std::string>& allowed) const {
        if (!v.is_object()) fail(ptr, "expected an object, got " + type_name(v));
        for (auto it = v.begin(); it != v.end(); ++it)
            if (std::find(allowed.begin(), allowed.end(), it.key()) == allowed.end())
                fail(ptr + "/" + json_pointer_token(it.key()), "unknown key '" + it.key() + "' (expected one of: " + join(allowed) + ")");
    }

    void exclusive(const json& v, const std::string& ptr, const std::vector<std::string>& keys) const {
        std::vector<std::string> present;
        for (const auto& k : keys)
            if (v.contains(k)) present.push_back(k);
        if (present.size() > 1) fail(ptr, "keys " + join(present) + " cannot be given together");
    }

    float number(const json& v, const std::string& ptr) const {
        if (!v.is_number()) fail(ptr, "expected a number, got " + type_name(v));
        const double d = v.get<double>();
        if (!std::isfinite(d)) fail(ptr, "expected a finite number");
        // Values are stored in single precision: 1e300 would silently become infinity.
        if (std::abs(d) > double(std::numeric_limits<float>::max()))
            fail(ptr, number_as_given(d) + " is out of range (single precision holds at most ±3.4e38)");
        return float(d);
    }
    float positive(const json& v, const std::string& ptr) const {
        const float x = number(v, ptr);
        const double given = v.get<double>();
        if (!(given > 0)) fail(ptr, "expected a positive number, got " + number_as_given(given));
        if (!(x > 0)) fail(ptr, number_as_given(given) + " is too small (single precision holds positive numbers from 1.4e-45)");
        return x;
    }
    std::string string(const json& v, const std::string& ptr) const {
        if (!v.is_string()) fail(ptr, "expected a string, got " + type_name(v));
        return v.get<std::string>();
    }
    std::vector<float> numbers(const json& v, const std::string& ptr, size_t n) const {
        if (!v.is_array() || v.size() != n)
            fail(ptr, "expected an array of " + std::to_string(n) + " numbers, got " +
                          (v.is_array() ? "an array of " + std::to_string(v.size()) : type_name(v)));
        std::vector<float> out;
        for (size_t i = 0; i < n; ++i) out.push_back(number(v[i], ptr + "/" + std::to_string(i)));
        return out;
    }
    Vec3 vec3(const json& v, const std::string& ptr) const {
        auto a = numbers(v, ptr, 3);
        return {a[0], a[1], a[2]};
    }
    // A number (grey) or [r, g, b]; never negative.
    Vec3 color(const json& v, const std::string& ptr) const {
        Vec3 c;
        if (v.is_number()) c = Vec3(number(v, ptr));
        else if (v.is_array()) c = vec3(v, ptr);
        else fail(ptr, "expected a number or an array of 3 numbers, got " + type_name(v));
        if (c.x < 0 || c.y < 0 || c.z < 0) fail(ptr, "colour components must not be negative");
        return c;
    }
    Quat quaternion(const json& v, const std::string& ptr) const {
        auto a = numbers(v, ptr, 4);
        Quat q(a[0], a[1], a[2], a[3]);
        const float len = glm::length(q);
        if (!(len > 1e-6f)) fail(ptr, "quaternion [w, x, y, z] must not be zero");
        return q / len;
    }
    const std::string& file() const { return file_; }

private:
    std::string file_;
};

// Rotation by x, then y, then z degrees about the fixed axes.
Quat euler_degrees(const Vec3& d) {
    const Vec3 r = glm::radians(d);
    return glm::angleAxis(r.z, Vec3(0, 0, 1)) * glm::angleAxis(r.y, Vec3(0, 1, 0)) * glm::angleAxis(r.x, Vec3(1, 0, 0));
}

Quat look_rotation(const Vec3& forward, const Vec3& up_hint) {
    const Vec3 f = glm::normalize(forward);
    Vec3 r = glm::cross(f, up_hint);
    if (glm::length(r) < 1e-6f) r = glm::cross(f, std::abs(f.y) < 0.9f ? Vec3(0, 1, 0) : Vec3(1, 0, 0));
    r = glm::normalize(r);
    const Vec3 u = glm::cross(r, f);
    Mat3 m(r, u, -f);  // columns: camera +X, +Y, +Z in world space
    return glm::normalize(glm::quat_cast(m));
}

bool same_material(const Material& a, const Material& b) {
    return a.name == b.name && a.albedo == b.albedo && a.specular == b.specular &&
           a.phong_exponent == b.phong_exponent && a.emission == b.emission && a.albedo_texture == b.albedo_texture &&
           a.emission_texture == b.emission_texture && a.normal_texture == b.normal_texture &&
           a.normal_scale == b.normal_scale && a.alpha_mode == b.alpha_mode && a.alpha == b.alpha &&
           a.alpha_cutoff == b.alpha_cutoff && a.alpha_texture == b.alpha_texture;
}

struct SceneBuilder {
    const Reader& in;
    const AssetPaths& assets;
    fs::path json_dir;
    Scene scene;
    std::map<std::string, uint32_t> named_materials;
    std::map<std::string, Scene> loaded;  // by resolved path: a file used twice loads once
    std::map<std::string, std::pair<std::string, std::set<std::string>>> warning_counts;  // text after the file name
    std::vector<std::string> warning_order;

    uint32_t add_material(const Material& m) {
        for (size_t i = 0; i < scene.materials.size(); ++i)
            if (same_material(scene.materials[i], m)) return uint32_t(i);
        scene.materials.push_back(m);
        return uint32_t(scene.materials.size() - 1);
    }

    fs::path resolve(const std::string& name, const std::string& ptr) {
        try {
            if (auto found = assets.find(name)) return *found;
            const fs::path local = json_dir / name;
            if (regular_file_exists(local)) return local;
        } catch (const Error& e) {  // a device, FIFO or directory by that name
            in.fail(ptr, "'" + name + "': " + e.what());
        }
        std::string searched = "the working directory";
        if (!assets.dirs().empty()) searched += ", " + assets.describe();
        searched += ", " + (json_dir.empty() ? std::string(".") : json_dir.string());
        in.fail(ptr, "file '" + name + "' not found in " + searched);
    }

    const Scene& load(const std::string& name, const std::string& ptr) {
        const fs::path path = resolve(name, ptr);
        const std::string key = fs::weakly_canonical(path).string();
        auto it = loaded.find(key);
        if (it != loaded.end()) return it->second;
        try {
            return loaded.emplace(key, load_mesh_file(path)).first->second;
        } catch (const Error& e) {
            in.fail(ptr, e.what());
        }
    }

    // Appends a loaded file under `parent`; its roots and world-space lights follow it.
    void merge(const Scene& sub, uint32_t parent, std::optional<uint32_t> override_material) {
        std::vector<uint32_t> remap(sub.materials.size());
        if (!override_material)
            for (size_t i = 0; i < sub.materials.size(); ++i) remap[i] = add_material(sub.materials[i]);
        const uint32_t mesh_offset = uint32_t(scene.meshes.size());
        for (Mesh mesh : sub.meshes) {
            for (uint32_t& id : mesh.material_ids) id = override_material ? *override_material : remap[id];
            scene.meshes.push_back(std::move(mesh));
        }
        const int node_offset = int(scene.nodes.size());
        const int skin_offset = int(scene.skins.size());
        for (SceneNode node : sub.nodes) {
            node.parent = node.parent >= 0 ? node.parent + node_offset : int(parent);
            for (uint32_t& m : node.meshes) m += mesh_offset;
            if (node.skin >= 0) node.skin += skin_offset;
            scene.nodes.push_back(std::move(node));
        }
        for (Skin skin : sub.skins) {
            for (uint32_t& j : skin.joints) j += uint32_t(node_offset);
            scene.skins.push_back(std::move(skin));
        }
        for (PunctualLight light : sub.lights) {
            light.node = light.node >= 0 ? light.node + node_offset : int(parent);
            scene.lights.push_back(light);
        }
        scene.degenerate_triangles_dropped += sub.degenerate_triangles_dropped;
        // The same note from many files (e.g. 174 kitchen parts) is reported once.
        for (const std::string& w : sub.warnings) {
            std::string what = w;
            if (what.rfind(sub.source, 0) == 0) what = what.substr(sub.source.size());
            auto [it, inserted] = warning_counts.try_emplace(what, w, std::set<std::string>{});
            it->second.second.insert(sub.source);
            if (inserted) warning_order.push_back(what);
        }
    }

    void finish_warnings() {
        for (const std::string& what : warning_order) {
            const auto& [first, sources] = warning_counts[what];
            const size_t n = sources.size();
            scene.warnings.push_back(n <= 1 ? first : first + " (and " + std::to_string(n - 1) + " more files)");
        }
    }

    // Bounds of the subtree rooted at `root` (every node after it belongs to it), with
    // the root's local transform replaced by `root_local`. Skinned meshes are measured in
    // their rest (bind) pose, placed by their joints as evaluate() places them.
    Bounds3 subtree_bounds(uint32_t root, const Transform& root_local) const {
        std::vector<Mat4> world(scene.nodes.size(), Mat4(1.0f));
        for (size_t i = root; i < scene.nodes.size(); ++i) {
            const SceneNode& n = scene.nodes[i];
            const Mat4 local = i == root ? root_local.matrix() : n.local.matrix();
            world[i] = (i == root || n.parent < 0) ? local : world[size_t(n.parent)] * local;
        }
        Bounds3 b;
        std::vector<Vec3> posed, normals;
        for (size_t i = root; i < scene.nodes.size(); ++i) {
            const SceneNode& n = scene.nodes[i];
            for (uint32_t m : n.meshes) {
                const Mesh& mesh = scene.meshes[m];
                if (n.skin >= 0 && !mesh.influences.empty()) {
                    skin_vertices(mesh, joint_matrices(scene.skins[size_t(n.skin)], world), posed, normals);
                    for (const Vec3& p : posed) b.extend(p);
                } else {
                    for (const Vec3& p : mesh.positions) b.extend(Vec3(world[i] * Vec4(p, 1.0f)));
                }
            }
        }
        return b;
    }

    void read_materials(const json& doc) {
        if (!doc.contains("materials")) return;
        const json& mats = doc["materials"];
        if (!mats.is_object()) in.fail("/materials", "expected an object mapping names to materials, got " + type_name(mats));
        for (auto it = mats.begin(); it != mats.end(); ++it) {
            const std::string ptr = "/materials/" + json_pointer_token(it.key());
            const json& v = it.value();
            in.check_object(v, ptr, {"albedo", "specular", "phong_exponent", "roughness", "emission"});
            in.exclusive(v, ptr, {"phong_exponent", "roughness"});
            Material m;
            m.name = it.key();
            if (v.contains("albedo")) m.albedo = in.color(v["albedo"], ptr + "/albedo");
            if (v.contains("specular")) m.specular = in.color(v["specular"], ptr + "/specular");
            if (v.contains("phong_exponent")) {
                m.phong_exponent = in.number(v["phong_exponent"], ptr + "/phong_exponent");
                if (m.phong_exponent < 0) in.fail(ptr + "/phong_exponent", "must not be negative");
            }
            if (v.contains("roughness")) {
                const float r = in.number(v["roughness"], ptr + "/roughness");
                if (r < 0 || r > 1) in.fail(ptr + "/roughness", "must be in [0, 1]");
                m.phong_exponent = exponent_from_roughness(r);
            }
            if (v.contains("emission")) m.emission = in.color(v["emission"], ptr + "/emission");
            for (int c = 0; c < 3; ++c)
                if (m.albedo[c] + m.specular[c] > 1.0f)
                    in.fail(ptr, "albedo + specular exceeds 1 (the material would create energy)");
            scene.materials.push_back(m);
            named_materials[it.key()] = uint32_t(scene.materials.size() - 1);
        }
    }

    void read_meshes(const json& doc) {
        if (!doc.contains("meshes")) in.fail("/meshes", "missing: a scene needs at least one mesh");
        const json& meshes = doc["meshes"];
        if (!meshes.is_array() || meshes.empty())
            in.fail("/meshes", "expected a non-empty array of meshes, got " + (meshes.is_array() ? std::string("an empty array") : type_name(meshes)));
        for (size_t i = 0; i < meshes.size(); ++i) {
            const std::string ptr = "/meshes/" + std::to_string(i);
            const json& e = meshes[i];
            in.check_object(e, ptr, {"file", "files", "name", "translate", "rotate_degrees", "rotate_quaternion", "scale",
                                     "material", "fit_to_box"});
            in.exclusive(e, ptr, {"file", "files"});
            in.exclusive(e, ptr, {"rotate_degrees", "rotate_quaternion"});
            in.exclusive(e, ptr, {"fit_to_box", "translate"});
            in.exclusive(e, ptr, {"fit_to_box", "scale"});
            std::vector<std::pair<std::string, std::string>> files;  // name, JSON path
            if (e.contains("file")) {
                files.emplace_back(in.string(e["file"], ptr + "/file"), ptr + "/file");
            } else if (e.contains("files")) {
                const json& list = e["files"];
                if (!list.is_array() || list.empty()) in.fail(ptr + "/files", "expected a non-empty array of file names");
                for (size_t k = 0; k < list.size(); ++k) {
                    const std::string p = ptr + "/files/" + std::to_string(k);
                    files.emplace_back(in.string(list[k], p), p);
                }
            } else {
                in.fail(ptr, "missing 'file' (or 'files')");
            }

            Transform local;
            if (e.contains("translate")) local.translation = in.vec3(e["translate"], ptr + "/translate");
            if (e.contains("rotate_degrees")) local.rotation = euler_degrees(in.vec3(e["rotate_degrees"], ptr + "/rotate_degrees"));
            if (e.contains("rotate_quaternion")) local.rotation = in.quaternion(e["rotate_quaternion"], ptr + "/rotate_quaternion");
            if (e.contains("scale")) {
                const json& s = e["scale"];
                const std::string sp = ptr + "/scale";
                if (s.is_number()) local.scale = Vec3(in.number(s, sp));
                else if (s.is_array()) local.scale = in.vec3(s, sp);
                else in.fail(sp, "expected a number or an array of 3 numbers, got " + type_name(s));
                if (local.scale.x == 0 || local.scale.y == 0 || local.scale.z == 0) in.fail(sp, "scale must not be zero");
            }
            std::optional<uint32_t> override_material;
            if (e.contains("material")) {
                const std::string name = in.string(e["material"], ptr + "/material");
                auto it = named_materials.find(name);
                if (it == named_materials.end())
                    in.fail(ptr + "/material", "material '" + name + "' is not defined in /materials");
                override_material = it->second;
            }

            SceneNode entry;
            entry.name = e.contains("name") ? in.string(e["name"], ptr + "/name") : fs::path(files.front().first).stem().string();
            entry.local = local;
            const uint32_t entry_index = uint32_t(scene.nodes.size());
            scene.nodes.push_back(entry);
            entry_nodes.push_back(entry_index);
            for (const auto& [name, fptr] : files) merge(load(name, fptr), entry_index, override_material);

            if (e.contains("fit_to_box")) {
                const std::string bp = ptr + "/fit_to_box";
                const json& box = e["fit_to_box"];
                in.check_object(box, bp, {"min", "max", "anchor"});
                if (!box.contains("min") || !box.contains("max")) in.fail(bp, "needs both 'min' and 'max'");
                const Vec3 lo = in.vec3(box["min"], bp + "/min"), hi = in.vec3(box["max"], bp + "/max");
                if (!(hi.x > lo.x && hi.y > lo.y && hi.z > lo.z)) in.fail(bp, "'max' must exceed 'min' on every axis");
                Transform rotate_only;
                rotate_only.rotation = local.rotation;
                const Bounds3 b = subtree_bounds(entry_index, rotate_only);
                if (b.empty()) in.fail(bp, "the mesh has no vertices to fit");
                const Vec3 extent = b.extent(), target = hi - lo;
                float s = kInfinity;
                for (int c = 0; c < 3; ++c)
                    if (extent[c] > 0) s = std::min(s, target[c] / extent[c]);
                if (!std::isfinite(s)) s = 1.0f;  // a single point: keep its size
                // "center": centred in the box; "bottom": centred in x and z, resting on min.y.
                std::string anchor = "center";
                if (box.contains("anchor")) anchor = in.string(box["anchor"], bp + "/anchor");
                if (anchor != "center" && anchor != "bottom")
                    in.fail(bp + "/anchor", "expected 'center' or 'bottom', got '" + anchor + "'");
                Transform fitted = rotate_only;
                fitted.scale = Vec3(s);
                fitted.translation = 0.5f * (lo + hi) - s * b.center();
                if (anchor == "bottom") fitted.translation.y = lo.y - s * b.min.y;
                scene.nodes[entry_index].local = fitted;
            }
        }
    }

    void read_lights(const json& doc) {
        if (!doc.contains("lights")) return;
        const json& lights = doc["lights"];
        if (!lights.is_array()) in.fail("/lights", "expected an array, got " + type_name(lights));
        for (size_t i = 0; i < lights.size(); ++i) {
            const std::string ptr = "/lights/" + std::to_string(i);
            const json& v = lights[i];
            if (!v.is_object()) in.fail(ptr, "expected an object, got " + type_name(v));
            if (!v.contains("type")) in.fail(ptr, "missing 'type' (point, spot or directional)");
            const std::string type = in.string(v["type"], ptr + "/type");
            PunctualLight light;
            light.name = "light" + std::to_string(i);
            if (type == "point") {
                in.check_object(v, ptr, {"type", "name", "position", "intensity", "power", "color"});
                light.type = LightType::Point;
            } else if (type == "spot") {
                in.check_object(v, ptr, {"type", "name", "position", "direction", "target", "intensity", "power", "color",
                                         "inner_angle_degrees", "outer_angle_degrees"});
                light.type = LightType::Spot;
            } else if (type == "directional") {
                in.check_object(v, ptr, {"type", "name", "direction", "intensity", "color"});
                light.type = LightType::Directional;
            } else {
                in.fail(ptr + "/type", "unknown light type '" + type + "' (expected point, spot or directional)");
            }
            if (v.contains("name")) light.name = in.string(v["name"], ptr + "/name");
            if (light.type != LightType::Directional) {
                if (!v.contains("position")) in.fail(ptr, "missing 'position'");
                light.position = in.vec3(v["position"], ptr + "/position");
            }
            if (light.type != LightType::Point) {
                in.exclusive(v, ptr, {"direction", "target"});
                Vec3 d;
                if (v.contains("direction")) d = in.vec3(v["direction"], ptr + "/direction");
                else if (v.contains("target")) d = in.vec3(v["target"], ptr + "/target") - light.position;
                else in.fail(ptr, "missing 'direction'" + std::string(light.type == LightType::Spot ? " (or 'target')" : ""));
                if (!(glm::length(d) > 0)) in.fail(ptr + (v.contains("direction") ? "/direction" : "/target"), "direction must not be zero");
                light.direction = glm::normalize(d);
            }
            if (light.type == LightType::Spot) {
                const float inner = v.contains("inner_angle_degrees") ? in.number(v["inner_angle_degrees"], ptr + "/inner_angle_degrees") : 0.0f;
                if (!v.contains("outer_angle_degrees")) in.fail(ptr, "missing 'outer_angle_degrees'");
                const float outer = in.number(v["outer_angle_degrees"], ptr + "/outer_angle_degrees");
                if (!(outer > 0 && outer <= 90)) in.fail(ptr + "/outer_angle_degrees", "must be in (0, 90]");
                if (inner < 0 || inner > outer) in.fail(ptr + "/inner_angle_degrees", "must be in [0, outer_angle_degrees]");
                light.cos_inner = std::cos(glm::radians(inner));
                light.cos_outer = std::cos(glm::radians(outer));
            }
            in.exclusive(v, ptr, {"intensity", "power"});
            const Vec3 color = v.contains("color") ? in.color(v["color"], ptr + "/color") : Vec3(1.0f);
            if (v.contains("intensity")) {
                light.intensity = in.color(v["intensity"], ptr + "/intensity") * color;
            } else if (v.contains("power")) {
                // Radiant power (W) spread over the sphere, or over the spot's cone.
                const Vec3 power = in.color(v["power"], ptr + "/power");
                const float solid_angle = light.type == LightType::Spot
                                              ? 2.0f * kPi * (1.0f - 0.5f * (light.cos_inner + light.cos_outer))
                                              : 4.0f * kPi;
                light.intensity = power / solid_angle * color;
            } else {
                in.fail(ptr, "missing 'intensity'" + std::string(light.type == LightType::Directional ? "" : " (or 'power')"));
            }
            scene.lights.push_back(light);
        }
    }

    void read_camera(const json& doc) {
        if (!doc.contains("camera")) return;
        const json& v = doc["camera"];
        in.check_object(v, "/camera", {"position", "target", "up", "vertical_fov_degrees"});
        SceneCamera cam;
        if (!v.contains("position") || !v.contains("target")) in.fail("/camera", "needs 'position' and 'target'");
        cam.position = in.vec3(v["position"], "/camera/position");
        cam.target = in.vec3(v["target"], "/camera/target");
        if (v.contains("up")) cam.up = in.vec3(v["up"], "/camera/up");
        if (v.contains("vertical_fov_degrees")) {
            cam.vertical_fov_degrees = in.number(v["vertical_fov_degrees"], "/camera/vertical_fov_degrees");
            if (!(cam.vertical_fov_degrees > 0 && cam.vertical_fov_degrees < 180))
                in.fail("/camera/vertical_fov_degrees", "must be in (0, 180)");
        }
        if (!(glm::length(cam.target - cam.position) > 0)) in.fail("/camera/target", "must differ from the position");
        if (!(glm::length(glm::cross(cam.target - cam.position, cam.up)) > 0))
            in.fail("/camera/up", "must not be parallel to the viewing direction");
        scene.camera = cam;
    }

    void read_hmd(const json& doc) {
        if (!doc.contains("hmd")) return;
        const json& v = doc["hmd"];
        in.check_object(v, "/hmd", {"preset", "position", "orientation_quaternion", "yaw_pitch_roll_degrees", "target", "ipd"});
        in.exclusive(v, "/hmd", {"orientation_quaternion", "yaw_pitch_roll_degrees", "target"});
        SceneHmd hmd;
        if (v.contains("preset")) {
            hmd.preset = in.string(v["preset"], "/hmd/preset");
            try {
                find_hmd_preset(hmd.preset);
            } catch (const Error& e) {
                in.fail("/hmd/preset", e.what());
            }
        }
        if (v.contains("position")) hmd.pose.position = in.vec3(v["position"], "/hmd/position");
        if (v.contains("orientation_quaternion"))
            hmd.pose.orientation = in.quaternion(v["orientation_quaternion"], "/hmd/orientation_quaternion");
        if (v.contains("yaw_pitch_roll_degrees")) {
            // Yaw about +Y, then pitch about the head's +X, then roll about its +Z;
            // all zero looks down −Z with +Y up.
            const Vec3 ypr = glm::radians(in.vec3(v["yaw_pitch_roll_degrees"], "/hmd/yaw_pitch_roll_degrees"));
            hmd.pose.orientation = glm::angleAxis(ypr.x, Vec3(0, 1, 0)) * glm::angleAxis(ypr.y, Vec3(1, 0, 0)) *
                                   glm::angleAxis(ypr.z, Vec3(0, 0, 1));
        }
        if (v.contains("target")) {
            const Vec3 d = in.vec3(v["target"], "/hmd/target") - hmd.pose.position;
            if (!(glm::length(d) > 0)) in.fail("/hmd/target", "must differ from the position");
            hmd.pose.orientation = look_rotation(d, Vec3(0, 1, 0));
        }
        if (v.contains("ipd")) {
            const float ipd = in.number(v["ipd"], "/hmd/ipd");
            if (!(ipd >= 0 && ipd < 1)) in.fail("/hmd/ipd", "must be in [0, 1) metres");
            hmd.ipd = ipd;
        }
        scene.hmd = hmd;
    }

    template <typename T, typename Parse>
    KeyframeChannel<T> read_channel(const json& v, const std::string& ptr, Parse parse) {
        in.check_object(v, ptr, {"times", "values"});
        if (!v.contains("times") || !v.contains("values")) in.fail(ptr, "needs 'times' and 'values'");
        const json& times = v["times"];
        const json& values = v["values"];
        if (!times.is_array() || times.empty()) in.fail(ptr + "/times", "expected a non-empty array of seconds");
        if (!values.is_array()) in.fail(ptr + "/values", "expected an array, got " + type_name(values));
        if (values.size() != times.size())
            in.fail(ptr + "/values", std::to_string(values.size()) + " values for " + std::to_string(times.size()) + " times");
        KeyframeChannel<T> c;
        for (size_t k = 0; k < times.size(); ++k) {
            const std::string tp = ptr + "/times/" + std::to_string(k);
            const float t = in.number(times[k], tp);
            if (k > 0 && !(t > c.times.back())) in.fail(tp, "times must be strictly increasing");
            c.times.push_back(t);
            c.values.push_back(parse(values[k], ptr + "/values/" + std::to_string(k)));
        }
        return c;
    }

    void read_animation(const json& doc) {
        if (!doc.contains("animation")) return;
        const json& v = doc["animation"];
        in.check_object(v, "/animation", {"frames_per_second", "nodes"});
        if (v.contains("frames_per_second")) {
            scene.frames_per_second = in.positive(v["frames_per_second"], "/animation/frames_per_second");
            if (scene.frames_per_second > kMaxFramesPerSecond)
                in.fail("/animation/frames_per_second", number_as_given(v["frames_per_second"].get<double>()) +
                                                            " is out of range (0, " + number_as_given(kMaxFramesPerSecond) + "]");
        }
        if (!v.contains("nodes")) return;
        const json& nodes = v["nodes"];
        if (!nodes.is_object()) in.fail("/animation/nodes", "expected an object keyed by mesh index or name");
        for (auto it = nodes.begin(); it != nodes.end(); ++it) {
            const std::string ptr = "/animation/nodes/" + json_pointer_token(it.key());
            const uint32_t node = entry_node_for(it.key(), ptr);
            const json& a = it.value();
            in.check_object(a, ptr, {"translation", "rotation", "rotation_degrees", "scale", "interpolation"});
            in.exclusive(a, ptr, {"rotation", "rotation_degrees"});
            TrsAnimation anim;
            if (a.contains("translation"))
                anim.translation = read_channel<Vec3>(a["translation"], ptr + "/translation",
                                                      [&](const json& x, const std::string& p) { return in.vec3(x, p); });
            if (a.contains("rotation"))
                anim.rotation = read_channel<Quat>(a["rotation"], ptr + "/rotation",
                                                   [&](const json& x, const std::string& p) { return in.quaternion(x, p); });
            if (a.contains("rotation_degrees"))
                anim.rotation = read_channel<Quat>(a["rotation_degrees"], ptr + "/rotation_degrees",
                                                   [&](const json& x, const std::string& p) { return euler_degrees(in.vec3(x, p)); });
            if (a.contains("scale"))
                anim.scale = read_channel<Vec3>(a["scale"], ptr + "/scale", [&](const json& x, const std::string& p) {
                    return x.is_number() ? Vec3(in.number(x, p)) : in.vec3(x, p);
                });
            if (a.contains("interpolation")) {
                const std::string mode = in.string(a["interpolation"], ptr + "/interpolation");
                if (mode == "step") anim.step = true;
                else if (mode != "linear") in.fail(ptr + "/interpolation", "expected 'linear' or 'step', got '" + mode + "'");
            }
            if (anim.empty()) in.fail(ptr, "no translation, rotation or scale keys");
            scene.nodes[node].animation = std::move(anim);
        }
    }

    uint32_t entry_node_for(const std::string& key, const std::string& ptr) const {
        if (!key.empty() && std::all_of(key.begin(), key.end(), [](char c) { return c >= '0' && c <= '9'; })) {
            const size_t i = std::stoul(key);
            if (i >= entry_nodes.size())
                in.fail(ptr, "mesh index " + key + " is out of range (the scene has " + std::to_string(entry_nodes.size()) + " meshes)");
            return entry_nodes[i];
        }
        std::optional<uint32_t> found;
        for (uint32_t n : entry_nodes)
            if (scene.nodes[n].name == key) {
                if (found) in.fail(ptr, "more than one mesh is named '" + key + "'");
                found = n;
            }
        if (!found) in.fail(ptr, "no mesh is named '" + key + "'");
        return *found;
    }

    std::vector<uint32_t> entry_nodes;  // node of each /meshes entry
};

}  // namespace

Scene load_scene_file(const fs::path& path, const AssetPaths& assets) {
    const std::string file = path.string();
    const std::string text = read_input_file(path);
    check_text_encoding(text, file, "scene JSON");
    const json doc = parse_json_document(text, file);

    Reader in(file);
    in.check_object(doc, "", {"name", "description", "materials", "meshes", "lights", "camera", "hmd", "animation"});
    SceneBuilder b{in, assets, path.parent_path(), {}, {}, {}, {}, {}, {}};
    b.scene.name = doc.contains("name") ? in.string(doc["name"], "/name") : path.stem().string();
    b.scene.source = file;
    if (doc.contains("description")) in.string(doc["description"], "/description");
    b.read_materials(doc);
    b.read_meshes(doc);
    b.finish_warnings();
    b.read_lights(doc);
    b.read_camera(doc);
    b.read_hmd(doc);
    b.read_animation(doc);
    b.scene.validate();
    return std::move(b.scene);
}

}  // namespace gilab
