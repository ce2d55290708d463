#pragma once
// Surface data at a ray hit, reconstructed from the world mesh.
#include "core/util/ray.hpp"
#include "core/scene/scene.hpp"

namespace gilab {

struct SurfaceInteraction {
    Vec3 position{0};
    Vec3 geometric_normal{0};   // unit, facing the incoming ray (flipped if needed)
    Vec3 shading_normal{0};     // unit, same hemisphere as geometric_normal
    Vec3 wo{0};                 // unit, towards the ray origin
    uint32_t material = 0;
    uint32_t mesh = kInvalidId, triangle = kInvalidId;
    bool back_face = false;     // the ray hit the side opposite the triangle's winding normal

    // Texture coordinates of each UV set at the hit, with the triangle's tangents along
    // them (world length per UV unit) and its UV units per world length (the square root
    // of UV area over world area; 0 when the mesh has no such set or it is degenerate).
    Vec2 uv[kUvSetCount]{};
    Vec3 dpdu[kUvSetCount]{}, dpdv[kUvSetCount]{};
    float uv_per_length[kUvSetCount]{};

    // Origin for a ray leaving the surface in direction d, offset to avoid self-hits.
    Vec3 spawn_origin(const Vec3& d) const;
};

SurfaceInteraction make_interaction(const SceneFrame& frame, const Ray& ray, const Hit& hit);

// Offset scaled to the magnitude of the position (robust for large scenes).
float ray_epsilon(const Vec3& p);

}  // namespace gilab
