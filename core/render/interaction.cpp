#include "core/render/interaction.hpp"

#include <cmath>
#include "core/util/error.hpp"

namespace gilab {

float ray_epsilon(const Vec3& p) {
    // A hit point rebuilt from barycentrics is off its triangle's plane by a few ulps of
    // its coordinates (~2e-7 relative); 2e-5 leaves a wide margin. Larger offsets bias
    // the image (the white furnace loses ~5e-5 of its one-bounce light at 1e-4), so the
    // margin is kept no wider than needed. Floor: unit-scale coordinates.
    float scale = std::max(1.0f, max_component(glm::abs(p)));
    return 2e-5f * scale;
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

    for (int k = 0; k < kUvSetCount; ++k) {
        const std::vector<Vec2>& uvs = mesh.uv_set(k);
        if (uvs.size() != mesh.positions.size()) continue;
        const Vec2 &t0 = uvs[tri.x], &t1 = uvs[tri.y], &t2 = uvs[tri.z];
        si.uv[k] = b0 * t0 + b1 * t1 + b2 * t2;
        const Vec2 d1 = t1 - t0, d2 = t2 - t0;
        const float det = d1.x * d2.y - d1.y * d2.x;
        if (!(std::abs(det) > 0.0f) || !(len > 0.0f)) continue;
        const Vec3 e1 = p1 - p0, e2 = p2 - p0;
        si.dpdu[k] = (d2.y * e1 - d1.y * e2) / det;
        si.dpdv[k] = (d1.x * e2 - d2.x * e1) / det;
        si.uv_per_length[k] = std::sqrt(std::abs(det) / len);
    }

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
