#include "core/scene/mesh.hpp"

#include "core/util/error.hpp"
#include "core/util/format.hpp"

namespace gilab {

Bounds3 Mesh::bounds() const {
    Bounds3 b;
    for (const Vec3& p : positions) b.extend(p);
    return b;
}

namespace {

std::string format_vec(const Vec3& v) {
    // Appended piece by piece: GCC 12 warns (-Wrestrict) on "(" + std::string.
    std::string text = "(";
    text += join(std::initializer_list<std::string>{number_as_given(v.x), number_as_given(v.y), number_as_given(v.z)});
    text += ")";
    return text;
}

// A triangle is dropped when two corners share an index, or when its area vanishes
// relative to its longest edge (collinear or coincident corners): such triangles have
// no geometric normal and only produce NaNs in shading.
bool is_degenerate(const Mesh& mesh, const UVec3& t) {
    if (t.x == t.y || t.y == t.z || t.x == t.z) return true;
    const glm::dvec3 a(mesh.positions[t.x]), b(mesh.positions[t.y]), c(mesh.positions[t.z]);
    const glm::dvec3 e0 = b - a, e1 = c - a, e2 = c - b;
    const double longest2 = std::max({glm::dot(e0, e0), glm::dot(e1, e1), glm::dot(e2, e2)});
    const double twice_area = glm::length(glm::cross(e0, e1));
    if (!(longest2 > 0) || twice_area <= 1e-10 * longest2) return true;
    // The float cross product is what the renderer computes; it must not vanish either.
    const Vec3 fc = glm::cross(mesh.positions[t.y] - mesh.positions[t.x],
                               mesh.positions[t.z] - mesh.positions[t.x]);
    return !(glm::dot(fc, fc) > 0.0f);
}

}  // namespace

std::string mesh_label(const Mesh& mesh) {
    return mesh.name.empty() ? std::string("mesh") : "mesh '" + mesh.name + "'";
}

MeshCleanupReport validate_and_clean(Mesh& mesh, size_t material_count, const std::string& source) {
    const std::string label = mesh_label(mesh);
    const size_t nv = mesh.positions.size();
    for (size_t i = 0; i < nv; ++i)
        if (!is_finite(mesh.positions[i]))
            throw Error(source, label + ": vertex " + std::to_string(i) + " has a non-finite position " +
                                    format_vec(mesh.positions[i]));
    for (size_t i = 0; i < nv; ++i)
        if (max_component(glm::abs(mesh.positions[i])) > kMaxCoordinate)
            throw Error(source, label + ": vertex " + std::to_string(i) + " at " + format_vec(mesh.positions[i]) +
                                    " lies beyond the supported coordinate range of ±1e18");
    if (!mesh.normals.empty()) {
        if (mesh.normals.size() != nv)
            throw Error(source, label + ": " + std::to_string(mesh.normals.size()) + " normals for " +
                                    std::to_string(nv) + " vertices");
        for (size_t i = 0; i < nv; ++i)
            if (!is_finite(mesh.normals[i]))
                throw Error(source, label + ": vertex " + std::to_string(i) + " has a non-finite normal " +
                                        format_vec(mesh.normals[i]));
    }
    for (const std::vector<Vec2>* set : {&mesh.uvs, &mesh.uvs1}) {
        if (set->empty()) continue;
        const std::string which = set == &mesh.uvs ? "texture coordinates" : "second-set texture coordinates";
        if (set->size() != nv)
            throw Error(source, label + ": " + std::to_string(set->size()) + " " + which + " for " +
                                    std::to_string(nv) + " vertices");
        for (size_t i = 0; i < nv; ++i)
            if (!std::isfinite((*set)[i].x) || !std::isfinite((*set)[i].y))
                throw Error(source, label + ": vertex " + std::to_string(i) + " has a non-finite texture coordinate");
    }
    // A mesh built without materials uses material 0 throughout.
    if (mesh.material_ids.empty() && material_count > 0) mesh.material_ids.assign(mesh.triangles.size(), 0);
    if (mesh.material_ids.size() != mesh.triangles.size())
        throw Error(source, label + ": " + std::to_string(mesh.material_ids.size()) + " material ids for " +
                                std::to_string(mesh.triangles.size()) + " triangles");

    for (size_t i = 0; i < mesh.triangles.size(); ++i) {
        const UVec3& t = mesh.triangles[i];
        for (int k = 0; k < 3; ++k)
            if (t[k] >= nv)
                throw Error(source, label + ": triangle " + std::to_string(i) + " references vertex " +
                                        std::to_string(t[k]) + " but there are only " + std::to_string(nv) +
                                        " vertices (index out of range)");
        if (mesh.material_ids[i] >= material_count)
            throw Error(source, label + ": triangle " + std::to_string(i) + " uses material " +
                                    std::to_string(mesh.material_ids[i]) + " but there are only " +
                                    std::to_string(material_count) + " materials (index out of range)");
    }

    MeshCleanupReport report;
    size_t kept = 0;
    for (size_t i = 0; i < mesh.triangles.size(); ++i) {
        if (is_degenerate(mesh, mesh.triangles[i])) {
            ++report.degenerate_triangles_dropped;
            continue;
        }
        mesh.triangles[kept] = mesh.triangles[i];
        mesh.material_ids[kept] = mesh.material_ids[i];
        ++kept;
    }
    mesh.triangles.resize(kept);
    mesh.material_ids.resize(kept);
    return report;
}

}  // namespace gilab
