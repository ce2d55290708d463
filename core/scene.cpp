#include "core/scene.hpp"

#include <cmath>
#include "core/error.hpp"

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
    return int(std::floor(animation_duration() * frames_per_second + 1e-6)) + 1;
}

size_t Scene::triangle_count() const {
    size_t n = 0;
    for (const auto& node : nodes)
        for (uint32_t m : node.meshes) n += meshes[m].triangles.size();
    return n;
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

SceneFrame Scene::evaluate(double time) const {
    SceneFrame frame;
    frame.time = time;
    std::vector<Mat4> world = node_transforms(time);
    for (size_t i = 0; i < nodes.size(); ++i) {
        const Mat4& m = world[i];
        // Normals transform by the inverse transpose; a mirroring transform flips the
        // winding, which we undo so the geometric normal keeps pointing outwards.
        Mat3 normal_matrix = glm::transpose(glm::inverse(Mat3(m)));
        bool mirrored = glm::determinant(Mat3(m)) < 0;
        for (uint32_t mesh_index : nodes[i].meshes) {
            const Mesh& mesh = meshes[mesh_index];
            WorldMesh wm;
            wm.source_mesh = mesh_index;
            wm.node = uint32_t(i);
            wm.positions.reserve(mesh.positions.size());
            for (const Vec3& p : mesh.positions) {
                Vec3 q = Vec3(m * Vec4(p, 1.0f));
                wm.positions.push_back(q);
                frame.bounds.extend(q);
            }
            wm.normals.reserve(mesh.normals.size());
            for (const Vec3& n : mesh.normals) {
                Vec3 t = normal_matrix * n;
                float len = glm::length(t);
                wm.normals.push_back(len > 0 ? t / len : Vec3(0, 0, 1));
            }
            wm.triangles = mesh.triangles;
            if (mirrored)
                for (UVec3& t : wm.triangles) std::swap(t.y, t.z);
            wm.material_ids = mesh.material_ids;
            frame.meshes.push_back(std::move(wm));
        }
    }
    for (const PunctualLight& light : lights) {
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

void Scene::validate() const {
    const std::string where = source.empty() ? name : source;
    if (meshes.empty() || triangle_count() == 0) throw Error(where, "scene has no triangles (empty scene)");
    for (size_t i = 0; i < nodes.size(); ++i) {
        const SceneNode& n = nodes[i];
        if (n.parent >= int(i)) throw Error(where, "node " + std::to_string(i) + " ('" + n.name + "') has parent " +
                                                       std::to_string(n.parent) + " that does not precede it");
        for (uint32_t m : n.meshes)
            if (m >= meshes.size())
                throw Error(where, "node " + std::to_string(i) + " references mesh " + std::to_string(m) +
                                       " but the scene has " + std::to_string(meshes.size()));
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
}

}  // namespace gilab
