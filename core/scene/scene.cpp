#include "core/scene/scene.hpp"

#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>
#include <string>
#include "core/util/error.hpp"
#include "core/util/format.hpp"
#include "core/scene/skin.hpp"

namespace gilab {

size_t SceneFrame::triangle_count() const {
    size_t n = 0;
    for (const auto& m : meshes) n += m.triangles.size();
    return n;
}

uint32_t Scene::add_mesh_instance(Mesh mesh, const Transform& transform) {
    meshes.push_back(std::move(mesh));
    SceneNode node;
    node.name = meshes.back().name;
    node.local = transform;
    node.meshes.push_back(uint32_t(meshes.size() - 1));
    nodes.push_back(std::move(node));
    return uint32_t(nodes.size() - 1);
}

bool Scene::is_animated() const {
    for (const auto& n : nodes)
        if (!n.animation.empty()) return true;
    return false;
}

double Scene::animation_duration() const {
    double d = 0;
    for (const auto& n : nodes) d = std::max(d, double(n.animation.duration()));
    return d;
}

int Scene::animation_frame_count() const {
    if (!is_animated()) return 1;
    const double frames = std::floor(animation_duration() * frames_per_second + 1e-6) + 1;
    if (!(frames >= 1)) return 1;
    return frames >= double(INT32_MAX) ? INT32_MAX : int(frames);  // never wraps negative
}

size_t Scene::triangle_count() const {
    size_t n = 0;
    for (const auto& node : nodes)
        for (uint32_t m : node.meshes) n += meshes[m].triangles.size();
    return n;
}

TextureUse Scene::texture_use() const {
    TextureUse use;
    std::set<const MipMap*> seen;
    for (const Material& m : materials) {
        use.textured_materials += m.has_textures();
        for (const TextureRef* t : {&m.albedo_texture, &m.emission_texture, &m.normal_texture, &m.alpha_texture})
            if (*t && seen.insert(t->image.get()).second) {
                ++use.images;
                use.bytes += t->image->bytes();
            }
    }
    return use;
}

bool Scene::has_emitters() const {
    if (!lights.empty()) return true;
    for (const auto& node : nodes)
        for (uint32_t m : node.meshes)
            for (uint32_t id : meshes[m].material_ids)
                if (materials[id].is_emissive()) return true;
    return false;
}

std::vector<Mat4> Scene::node_transforms(double time) const {
    std::vector<Mat4> world(nodes.size());
    for (size_t i = 0; i < nodes.size(); ++i) {
        const SceneNode& node = nodes[i];
        Transform local = node.animation.empty() ? node.local : node.animation.sample(float(time), node.local);
        Mat4 m = local.matrix();
        world[i] = node.parent >= 0 ? world[size_t(node.parent)] * m : m;
    }
    return world;
}

std::vector<Mat4> Scene::rest_node_transforms() const {
    std::vector<Mat4> world(nodes.size());
    for (size_t i = 0; i < nodes.size(); ++i) {
        const Mat4 m = nodes[i].local.matrix();
        world[i] = nodes[i].parent >= 0 ? world[size_t(nodes[i].parent)] * m : m;
    }
    return world;
}

namespace {

void place_rigid(const Mesh& mesh, const Mat4& m, WorldMesh& wm) {
    // Normals transform by the inverse transpose; a mirroring transform flips the
    // winding, which we undo so the geometric normal keeps pointing outwards.
    const Mat3 normal_matrix = glm::transpose(glm::inverse(Mat3(m)));
    wm.positions.reserve(mesh.positions.size());
    for (const Vec3& p : mesh.positions) wm.positions.push_back(Vec3(m * Vec4(p, 1.0f)));
    wm.normals.reserve(mesh.normals.size());
    for (const Vec3& n : mesh.normals) {
        Vec3 t = normal_matrix * n;
        float len = glm::length(t);
        wm.normals.push_back(len > 0 ? t / len : Vec3(0, 0, 1));
    }
    wm.triangles = mesh.triangles;
    if (glm::determinant(Mat3(m)) < 0)
        for (UVec3& t : wm.triangles) std::swap(t.y, t.z);
}

void place_skinned(const Mesh& mesh, std::span<const Mat4> joints, WorldMesh& wm) {
    skin_vertices(mesh, joints, wm.positions, wm.normals);
    wm.triangles = mesh.triangles;
    // Winding follows the first joint: a blend cannot flip it per triangle.
    if (!joints.empty() && glm::determinant(Mat3(joints[0])) < 0)
        for (UVec3& t : wm.triangles) std::swap(t.y, t.z);
}

// include: one flag per node, or null for every node.
SceneFrame flatten(const Scene& scene, const std::vector<Mat4>& world, double time, const std::vector<bool>* include) {
    SceneFrame frame;
    frame.time = time;
    frame.materials = scene.materials;
    std::vector<std::vector<Mat4>> joints(scene.skins.size());  // per skin, computed on first use
    for (size_t i = 0; i < scene.nodes.size(); ++i) {
        if (include && !(*include)[i]) continue;
        const SceneNode& node = scene.nodes[i];
        const bool skinned = node.skin >= 0;
        if (skinned && size_t(node.skin) >= scene.skins.size())
            throw Error(scene.source.empty() ? scene.name : scene.source,
                        "node " + std::to_string(i) + " references skin " + std::to_string(node.skin) + " (out of range)");
        if (skinned && joints[size_t(node.skin)].empty())
            joints[size_t(node.skin)] = joint_matrices(scene.skins[size_t(node.skin)], world);
        for (uint32_t mesh_index : node.meshes) {
            const Mesh& mesh = scene.meshes[mesh_index];
            WorldMesh wm;
            wm.source_mesh = mesh_index;
            wm.node = uint32_t(i);
            if (skinned && !mesh.influences.empty()) place_skinned(mesh, joints[size_t(node.skin)], wm);
            else place_rigid(mesh, world[i], wm);
            bool finite = true;
            for (const Vec3& q : wm.positions) {
                frame.bounds.extend(q);
                finite &= is_finite(q);
            }
            if (!finite)
                throw Error(scene.source.empty() ? scene.name : scene.source,
                            "node " + std::to_string(i) + " ('" + node.name + "') puts mesh '" + mesh.name +
                                "' at non-finite world positions at t = " + number_as_given(time) +
                                " s (its transform overflows)");
            wm.material_ids = mesh.material_ids;
            wm.uvs = mesh.uvs;
            wm.uvs1 = mesh.uvs1;
            frame.meshes.push_back(std::move(wm));
        }
    }
    for (const PunctualLight& light : scene.lights) {
        PunctualLight l = light;
        if (light.node >= 0 && size_t(light.node) < world.size()) {
            const Mat4& m = world[size_t(light.node)];
            l.position = Vec3(m * Vec4(light.position, 1.0f));
            Vec3 d = Mat3(m) * light.direction;
            l.direction = glm::length(d) > 0 ? glm::normalize(d) : light.direction;
        }
        frame.lights.push_back(l);
    }
    return frame;
}

}  // namespace

SceneFrame Scene::evaluate(double time) const { return flatten(*this, node_transforms(time), time, nullptr); }

SceneFrame Scene::evaluate(double time, const std::vector<bool>& include_nodes) const {
    if (include_nodes.size() != nodes.size())
        throw Error(source.empty() ? name : source,
                    "node selection has " + std::to_string(include_nodes.size()) + " entries but the scene has " +
                        std::to_string(nodes.size()) + " nodes");
    return flatten(*this, node_transforms(time), time, &include_nodes);
}

SceneFrame Scene::evaluate_rest() const { return flatten(*this, rest_node_transforms(), 0.0, nullptr); }

std::vector<bool> Scene::dynamic_nodes() const {
    // A skin does not move its node's children (they follow the node's own transform),
    // so only animation is inherited. Parents precede children: their flag is final.
    std::vector<bool> animated(nodes.size(), false), dynamic(nodes.size(), false);
    for (size_t i = 0; i < nodes.size(); ++i) {
        const SceneNode& node = nodes[i];
        const bool animated_parent = node.parent >= 0 && size_t(node.parent) < i && animated[size_t(node.parent)];
        animated[i] = !node.animation.empty() || animated_parent;
        dynamic[i] = animated[i] || node.skin >= 0;
    }
    return dynamic;
}

namespace {

// Bounds on what a node's transform can do over all time, in the ∞-norm: a point p of
// its meshes lands within offset + linear·|p| of the origin on every axis.
struct Reach {
    double linear = 1;
    double offset = 0;
};

double max_abs(const Vec3& v) { return std::max({std::abs(double(v.x)), std::abs(double(v.y)), std::abs(double(v.z))}); }

// Local reach of a TRS node over its rest pose and every key (a rotation's ∞-norm is at
// most √3; interpolated values never exceed the keys').
Reach local_reach(const SceneNode& n) {
    double scale = max_abs(n.local.scale), shift = max_abs(n.local.translation);
    for (const Vec3& s : n.animation.scale.values) scale = std::max(scale, max_abs(s));
    for (const Vec3& t : n.animation.translation.values) shift = std::max(shift, max_abs(t));
    return {std::sqrt(3.0) * scale, shift};
}

template <typename Matrix>
Reach matrix_reach(const Matrix& m) {
    double linear = 0, offset = 0;
    for (int r = 0; r < 3; ++r) {
        linear = std::max(linear, std::abs(double(m[0][r])) + std::abs(double(m[1][r])) + std::abs(double(m[2][r])));
        offset = std::max(offset, std::abs(double(m[3][r])));
    }
    return {linear, offset};
}

// `outer` applied after `inner`.
Reach compose(const Reach& outer, const Reach& inner) {
    return {outer.linear * inner.linear, outer.offset + outer.linear * inner.offset};
}

glm::dmat4 rest_matrix(const Transform& t) {
    const glm::dquat rotation(double(t.rotation.w), double(t.rotation.x), double(t.rotation.y), double(t.rotation.z));
    return glm::translate(glm::dmat4(1.0), glm::dvec3(t.translation)) * glm::mat4_cast(rotation) *
           glm::scale(glm::dmat4(1.0), glm::dvec3(t.scale));
}

// A node's world transform as a bound for its animated ancestors (whose keys only give
// a worst case) followed by the exact product of the static nodes below the last of
// them. Per-node bounds multiplied down a chain grow geometrically (√3 per rotation,
// 3^50 for 100 identity nodes); the exact product of static nodes does not.
struct WorldReach {
    Reach animated{};             // up to and including the last animated ancestor
    glm::dmat4 static_part{1.0};  // the static nodes below it, composed exactly
    Reach reach() const { return compose(animated, matrix_reach(static_part)); }
};

WorldReach child_reach(const WorldReach& parent, const SceneNode& n) {
    if (n.animation.empty()) return {parent.animated, parent.static_part * rest_matrix(n.local)};
    return {compose(parent.reach(), local_reach(n)), glm::dmat4(1.0)};
}

std::string approx(double x) {
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%.3g", x);
    return buffer;
}

}  // namespace

void Scene::validate() const {
    const std::string where = source.empty() ? name : source;
    // Mesh references first: triangle_count() and everything below index meshes by them.
    for (size_t i = 0; i < nodes.size(); ++i)
        for (uint32_t m : nodes[i].meshes)
            if (m >= meshes.size())
                throw Error(where, "node " + std::to_string(i) + " references mesh " + std::to_string(m) +
                                       " but the scene has " + std::to_string(meshes.size()));
    if (meshes.empty() || triangle_count() == 0) throw Error(where, "scene has no triangles (empty scene)");
    if (!(std::isfinite(frames_per_second) && frames_per_second > 0))
        throw Error(where, "frames per second " + number_as_given(frames_per_second) + " must be a positive number");
    if (is_animated()) {
        const double frames = std::floor(animation_duration() * frames_per_second + 1e-6) + 1;
        if (!(frames <= kMaxAnimationFrames))
            throw Error(where, "the animation lasts " + approx(animation_duration()) + " s, which at " +
                                   approx(frames_per_second) + " frames per second is " + approx(frames) +
                                   " frames, more than the " + std::to_string(kMaxAnimationFrames) +
                                   " supported (check the key times and the frame rate)");
    }
    for (size_t i = 0; i < nodes.size(); ++i) {
        const SceneNode& n = nodes[i];
        if (n.parent >= int(i)) throw Error(where, "node " + std::to_string(i) + " ('" + n.name + "') has parent " +
                                                       std::to_string(n.parent) + " that does not precede it");
        if (n.skin < 0) continue;
        if (size_t(n.skin) >= skins.size())
            throw Error(where, "node " + std::to_string(i) + " ('" + n.name + "') references skin " +
                                   std::to_string(n.skin) + " but the scene has " + std::to_string(skins.size()));
        for (uint32_t m : n.meshes) {
            if (meshes[m].influences.empty())
                throw Error(where, "node " + std::to_string(i) + " ('" + n.name + "') is skinned but mesh '" +
                                       meshes[m].name + "' has no joint influences");
            check_influences(meshes[m], skins[size_t(n.skin)].joints.size(), where);
        }
    }
    for (size_t k = 0; k < skins.size(); ++k) {
        const Skin& skin = skins[k];
        const std::string label = "skin " + std::to_string(k) + (skin.name.empty() ? "" : " ('" + skin.name + "')");
        if (skin.joints.empty()) throw Error(where, label + " has no joints");
        if (skin.inverse_bind.size() != skin.joints.size())
            throw Error(where, label + " has " + std::to_string(skin.inverse_bind.size()) + " inverse bind matrices for " +
                                   std::to_string(skin.joints.size()) + " joints (count mismatch)");
        for (uint32_t j : skin.joints)
            if (j >= nodes.size())
                throw Error(where, label + " uses node " + std::to_string(j) + " as a joint but the scene has " +
                                       std::to_string(nodes.size()) + " nodes (joint index out of range)");
    }
    for (size_t i = 0; i < meshes.size(); ++i) {
        const Mesh& mesh = meshes[i];
        if (mesh.material_ids.size() != mesh.triangles.size())
            throw Error(where, "mesh '" + mesh.name + "' has " + std::to_string(mesh.material_ids.size()) +
                                   " material ids for " + std::to_string(mesh.triangles.size()) + " triangles");
        for (uint32_t id : mesh.material_ids)
            if (id >= materials.size())
                throw Error(where, "mesh '" + mesh.name + "' uses material " + std::to_string(id) +
                                       " but the scene has " + std::to_string(materials.size()));
    }
    for (const auto& l : lights)
        if (!is_finite(l.position) || !is_finite(l.direction) || !is_finite(l.intensity))
            throw Error(where, "light '" + l.name + "' has a non-finite position, direction or intensity");
    check_world_reach(where);
}

// A finite mesh under finite transforms can still overflow (scale 1e30 on a 1e10 model,
// matrix entries of 1e38): bound every node's reach before anything is rendered.
void Scene::check_world_reach(const std::string& where) const {
    std::vector<WorldReach> world_reach(nodes.size());
    std::vector<Reach> world(nodes.size());
    for (size_t i = 0; i < nodes.size(); ++i) {
        const SceneNode& n = nodes[i];
        auto finite_keys = [](const auto& channel) {
            for (const auto& v : channel.values)
                for (int c = 0; c < v.length(); ++c)
                    if (!std::isfinite(v[c])) return false;
            return true;
        };
        const Transform& t = n.local;
        if (!is_finite(t.translation) || !is_finite(t.scale) || !std::isfinite(glm::length(t.rotation)) ||
            !finite_keys(n.animation.translation) || !finite_keys(n.animation.rotation) || !finite_keys(n.animation.scale))
            throw Error(where, "node " + std::to_string(i) + " ('" + n.name + "') has a non-finite transform");
        world_reach[i] = child_reach(n.parent >= 0 ? world_reach[size_t(n.parent)] : WorldReach{}, n);
        world[i] = world_reach[i].reach();
    }
    std::vector<double> extent(meshes.size());  // largest |coordinate| of each mesh
    for (size_t m = 0; m < meshes.size(); ++m)
        for (const Vec3& p : meshes[m].positions) extent[m] = std::max(extent[m], max_abs(p));
    for (size_t i = 0; i < nodes.size(); ++i) {
        const SceneNode& n = nodes[i];
        for (uint32_t m : n.meshes) {
            double reach = world[i].offset + world[i].linear * extent[m];
            if (n.skin >= 0 && !meshes[m].influences.empty()) {
                const Skin& skin = skins[size_t(n.skin)];
                reach = 0;
                for (size_t j = 0; j < skin.joints.size(); ++j) {
                    const Reach& joint = world[skin.joints[j]];
                    const Reach bind = matrix_reach(skin.inverse_bind[j]);
                    reach = std::max(reach, joint.offset + joint.linear * (bind.offset + bind.linear * extent[m]));
                }
            }
            if (!(reach <= double(kMaxCoordinate)))
                throw Error(where, "node " + std::to_string(i) + " ('" + n.name + "') can carry mesh '" + meshes[m].name +
                                       "' to coordinates of about " + approx(reach) +
                                       ", beyond the supported range of ±1e18 (check its scale, translation or matrix)");
        }
    }
}

}  // namespace gilab
