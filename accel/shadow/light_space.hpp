#pragma once
// The voxel grid over a light's view volume (P2 §3.1). Light-space coordinates
// (u, v, w) are in voxel units: u, v across the beam (one texel of the light's depth
// map per voxel column), w along it (depth from the light), each in [0, N).
//  * Directional light: an orthographic box fitted to the scene bounds; x, y span the
//    box across the light direction, z its extent along it.
//  * Spot light: its perspective frustum. u, v are the projected position over the
//    cone's square of tangents; w is axial depth (distance along the spot axis),
//    linear between near and far planes fitted to the scene bounds.
//  * Point light: refused; LightShadowDags covers one with a cube of six spot frusta.
// Resolution N is any value from 8 to 2^17; the octrees over the grid have depth
// ceil(log2 N) and the columns or layers beyond N hold no geometry.
#include <cstdint>
#include "core/scene/light.hpp"
#include "core/util/math.hpp"
#include "core/util/ray.hpp"

namespace gilab {

inline constexpr uint32_t kMaxLightSpaceResolution = 1u << 17;

class LightSpace {
public:
    // Throws Error naming the light for a point light, a spot cone of 80° half-angle or
    // more, a zero direction, an empty or non-finite scene box, or a bad resolution.
    LightSpace(const PunctualLight& light, const Bounds3& scene_bounds, uint32_t resolution);
    // Whether any of the box can lie in the light's view volume: always for a directional
    // light, for a spot light some of the box is in front of it (the constructor refuses
    // the rest).
    static bool faces_any_of(const PunctualLight& light, const Bounds3& scene_bounds);

    uint32_t resolution() const { return n_; }
    int depth() const { return depth_; }                 // octree depth, ceil(log2 N)
    uint32_t octree_size() const { return 1u << depth_; }
    bool perspective() const { return perspective_; }

    // The ray sampling texel (x, y) at its centre; its hit distance t is the depth w
    // directly in voxel units (the direction is scaled accordingly).
    Ray texel_ray(uint32_t x, uint32_t y) const;
    // Continuous light-space coordinates of a world point (may fall outside [0, N)).
    DVec3 to_light(const Vec3& p) const;
    // Where a surface point is looked up: moved off the surface along its normal
    // (turned to face the light; callers skip surfaces turned away) by 1.5 voxels, then 1 voxel toward the light, so that a
    // lit surface does not shadow itself through depth quantization ("acne"). Both the
    // shadow map and the shadow DAGs look up this same point.
    DVec3 lookup_coords(const Vec3& p, const Vec3& normal) const;
    // Whether the triangle may overlap the view volume: false only when all three corners
    // lie outside one of its bounding planes (the four sides of a spot frustum and the
    // plane through the light), so no triangle that overlaps is ever missed, however
    // small. A directional light's box encloses the scene: always true.
    bool may_overlap_triangle(const Vec3& a, const Vec3& b, const Vec3& c) const;
    // World size of one voxel near p (the larger of its across-beam and depth sizes).
    float voxel_world_size(const Vec3& p) const;
    // Unit direction from p toward the light.
    Vec3 to_light_direction(const Vec3& p) const;
    // Whether a surface with this normal at p is turned toward the light. One turned
    // away is unlit by its own object, whatever a structure would answer.
    bool faces_light(const Vec3& p, const Vec3& normal) const { return glm::dot(normal, to_light_direction(p)) > 0; }
    // Unit axes of the grid in world space: across the beam (x, y) and along it (z); for
    // a spot light, those of its central axis.
    const Vec3& axis_x() const { return right_; }
    const Vec3& axis_y() const { return up_; }
    const Vec3& axis_z() const { return dir_; }

private:
    uint32_t n_ = 0;
    int depth_ = 0;
    bool perspective_ = false;
    Vec3 right_{1, 0, 0}, up_{0, 1, 0}, dir_{0, 0, 1};
    // Directional: box [lo, lo + ext) along right, up, dir. Spot: position, tangent of
    // the half-angle, axial near and far.
    DVec3 lo_{0}, ext_{1};
    Vec3 position_{0};
    double tan_half_ = 1, near_ = 0, far_ = 1;
};

}  // namespace gilab
