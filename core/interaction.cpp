#include "core/interaction.hpp"

#include <cmath>
#include "core/error.hpp"

namespace gilab {

float ray_epsilon(const Vec3& p) {
    // float keeps ~7 digits, so a hit point is only known to a few ulps of its largest
    // coordinate; stay well above that, with an absolute floor near the origin.
    float scale = std::max(1.0f, max_component(glm::abs(p)));
    return 1e-4f * scale;
}

Vec3 SurfaceInteraction::spawn_origin(const Vec3& d) const {
    float eps = ray_epsilon(position);
    return glm::dot(d, geometric_normal) >= 0.0f ? position + eps * geometric_normal
                                                 : position - eps * geometric_normal;
}

SurfaceInteraction make_interaction(const SceneFrame& frame, const Ray& ray, const Hit& hit) {
    if (!hit.valid() || hit.mesh >= frame.meshes.size())
        throw Error("make_interaction", "hit does not reference a mesh of the scene frame");
    const WorldMesh& mesh = frame.meshes[hit.mesh];
    if (hit.triangle >= mesh.triangles.size())
        throw Error("make_interaction", "hit triangle " + std::to_string(hit.triangle) + " out of range");
    const UVec3 tri = mesh.triangles[hit.triangle];
    const Vec3 &p0 = mesh.positions[tri.x], &p1 = mesh.positions[tri.y], &p2 = mesh.positions[tri.z];
    const float b1 = hit.u, b2 = hit.v, b0 = 1.0f - b1 - b2;

    SurfaceInteraction si;
    si.mesh = hit.mesh;
    si.triangle = hit.triangle;
    si.material = hit.triangle < mesh.material_ids.size() ? mesh.material_ids[hit.triangle] : 0;
    // Barycentric interpolation lands on the triangle's plane (ray.at(t) may not).
    si.position = b0 * p0 + b1 * p1 + b2 * p2;
    si.wo = -glm::normalize(ray.direction);

    Vec3 ng = glm::cross(p1 - p0, p2 - p0);
    float len = glm::length(ng);
    ng = len > 0.0f ? ng / len : (glm::length(hit.geometric_normal) > 0 ? glm::normalize(hit.geometric_normal)
                                                                        : si.wo);
    si.back_face = glm::dot(ng, si.wo) < 0.0f;
    si.geometric_normal = si.back_face ? -ng : ng;

    si.shading_normal = si.geometric_normal;
    if (!mesh.normals.empty()) {
        Vec3 ns = b0 * mesh.normals[tri.x] + b1 * mesh.normals[tri.y] + b2 * mesh.normals[tri.z];
        float ls = glm::length(ns);
        if (ls > 0.0f && std::isfinite(ls)) {
            ns /= ls;
            // Vertex normals may disagree with the winding; keep them on the side the ray hit.
            if (glm::dot(ns, si.geometric_normal) < 0.0f) ns = -ns;
            si.shading_normal = ns;
        }
    }
    return si;
}

}  // namespace gilab
