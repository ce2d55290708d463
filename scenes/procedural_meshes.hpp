#pragma once
// Small procedural meshes for built-in scenes. The solids (box, prism, cone, gable prism)
// are closed 2-manifolds with shared vertices and outward winding, so closed-mesh tests
// and solid (inside/outside) voxelization accept them; the heightfield is one open sheet
// facing +Y. All are flat-shaded except the heightfield, which carries vertex normals.
#include <cstdint>
#include <functional>
#include <string>
#include "core/scene/mesh.hpp"

namespace gilab {

// Axis-aligned box between two corners: 8 vertices, 12 triangles.
Mesh make_box(const std::string& name, const Vec3& min, const Vec3& max, uint32_t material);

// Upright regular n-gon prism (a round tower for n ≈ 12): base centre, circumradius,
// height, capped at both ends. `start_degrees` turns the first corner about +Y from +X.
Mesh make_prism(const std::string& name, const Vec3& base_centre, float radius, float height, int sides,
                uint32_t material, float start_degrees = 0.0f);

// Upright regular n-gon cone / pyramid with its base capped (a tower roof).
Mesh make_cone(const std::string& name, const Vec3& base_centre, float radius, float height, int sides,
               uint32_t material, float start_degrees = 0.0f);

// Gable roof: a triangular prism over the rectangle [min.x, max.x] × [min.z, max.z] at
// height min.y, with its ridge `ridge_height` above, running along X (or along Z).
Mesh make_gable_prism(const std::string& name, const Vec3& min, const Vec3& max, float ridge_height,
                      bool ridge_along_x, uint32_t material);

// Open heightfield: nx × nz vertices evenly spread over [min.x, max.x] × [min.y, max.y]
// in world X/Z, vertex y = height(x, z); per-vertex normals from central differences.
Mesh make_heightfield(const std::string& name, int nx, int nz, const Vec2& min, const Vec2& max,
                      const std::function<float(float, float)>& height, uint32_t material);

// Signed volume enclosed by a triangle mesh (divergence theorem): positive when a closed
// mesh is wound outwards.
double signed_volume(const Mesh& mesh);

}  // namespace gilab
