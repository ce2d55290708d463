#include "core/scene/skin.hpp"

#include "core/util/error.hpp"
#include "core/scene/mesh.hpp"

namespace gilab {

namespace {

std::string skin_label(const Skin& skin) { return skin.name.empty() ? std::string("skin") : "skin '" + skin.name + "'"; }


}  // namespace

std::vector<Mat4> joint_matrices(const Skin& skin, std::span<const Mat4> world) {
    // Scene::validate() reports these with the scene's name; here they only stop a crash.
    if (skin.inverse_bind.size() != skin.joints.size())
        throw Error(skin_label(skin), "inverse bind matrices and joints differ in count (count mismatch)");
    std::vector<Mat4> out(skin.joints.size());
    for (size_t k = 0; k < skin.joints.size(); ++k) {
        if (skin.joints[k] >= world.size())
            throw Error(skin_label(skin), "joint node " + std::to_string(skin.joints[k]) + " is out of range");
        out[k] = world[skin.joints[k]] * skin.inverse_bind[k];
    }
    return out;
}

void skin_vertices(const Mesh& mesh, std::span<const Mat4> joints, std::vector<Vec3>& positions,
                   std::vector<Vec3>& normals) {
    const size_t n = mesh.positions.size();
    if (mesh.influences.size() != n)
        throw Error(mesh_label(mesh), std::to_string(mesh.influences.size()) + " joint influences for " +
                                          std::to_string(n) + " vertices (count mismatch)");
    positions.resize(n);
    normals.resize(mesh.normals.size());
    for (size_t v = 0; v < n; ++v) {
        const VertexInfluences& in = mesh.influences[v];
        // Zero-weight slots are skipped, so a vertex bound to one joint gets exactly that
        // joint's matrix (1·J is exact), not a sum perturbed by rounding.
        Mat4 m(0.0f);
        for (int k = 0; k < 4; ++k) {
            if (in.weights[k] == 0.0f) continue;
            const size_t j = in.joints[size_t(k)];
            if (j >= joints.size())
                throw Error(mesh_label(mesh), "vertex " + std::to_string(v) + " uses joint " + std::to_string(j) +
                                                  " of " + std::to_string(joints.size()) + " (joint index out of range)");
            m += in.weights[k] * joints[j];
        }
        positions[v] = Vec3(m * Vec4(mesh.positions[v], 1.0f));
        if (normals.empty()) continue;
        // The cofactor matrix is det·M⁻ᵀ: no inverse needed, and the sign of det keeps a
        // mirroring blend's normals on the same side as the rigid path's.
        const Vec3 c0(m[0]), c1(m[1]), c2(m[2]);
        const Mat3 cof(glm::cross(c1, c2), glm::cross(c2, c0), glm::cross(c0, c1));
        Vec3 t = cof * mesh.normals[v];
        if (glm::dot(c0, cof[0]) < 0.0f) t = -t;
        const float len = glm::length(t);
        normals[v] = len > 0.0f ? t / len : Vec3(0, 0, 1);
    }
}

void check_influences(const Mesh& mesh, size_t joint_count, const std::string& source) {
    const std::string label = mesh_label(mesh);
    if (mesh.influences.size() != mesh.positions.size())
        throw Error(source, label + ": " + std::to_string(mesh.influences.size()) + " joint influences for " +
                                std::to_string(mesh.positions.size()) + " vertices (count mismatch)");
    for (size_t v = 0; v < mesh.influences.size(); ++v) {
        const VertexInfluences& in = mesh.influences[v];
        float sum = 0.0f;
        for (int k = 0; k < 4; ++k) {
            const float w = in.weights[k];
            if (!std::isfinite(w) || w < 0.0f)
                throw Error(source, label + ": vertex " + std::to_string(v) + " has a negative or non-finite joint weight");
            if (w > 0.0f && in.joints[size_t(k)] >= joint_count)
                throw Error(source, label + ": vertex " + std::to_string(v) + " uses joint " +
                                        std::to_string(in.joints[size_t(k)]) + " but its skin has " +
                                        std::to_string(joint_count) + " joints (joint index out of range)");
            sum += w;
        }
        if (!(std::abs(sum - 1.0f) <= 1e-3f))
            throw Error(source, label + ": vertex " + std::to_string(v) + " has joint weights summing to " +
                                    std::to_string(sum) + ", not 1");
    }
}

}  // namespace gilab
