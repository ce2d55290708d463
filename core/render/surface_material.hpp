#pragma once
// A material resolved at a surface point: its textures looked up at the hit's texture
// coordinates, over the footprint of the ray that found it.
//
// Footprints follow ray cones (Akenine-Möller et al., "Texture Level of Detail
// Strategies for Real-Time Ray Tracing", Ray Tracing Gems, 2019): a ray carries a cone
// whose width at the hit is `cone_width` (world units, across the ray); on the surface
// it covers cone_width / |cos θ| of world length, which the triangle's UV density turns
// into a footprint in texture coordinates and so into a mip level. A cone width of 0
// is a point lookup at the finest level: for hits that carry no footprint (photons,
// voxelization samples), each technique states where it uses it.
//
// Normal maps bend the shading normal in the tangent frame of the map's UV set (x along
// +u, y towards the image's top row, z the interpolated normal; glTF's convention). The
// bent normal is kept at least slightly above the geometric normal's side, so a mapped
// normal never puts the viewer below the surface; the reflection model then uses it as
// it uses any shading normal.
#include "core/render/interaction.hpp"
#include "core/scene/material.hpp"

namespace gilab {

// Width of a ray cone at distance `distance` from its apex; `spread` is the cone's full
// angle in radians (a pixel's angle for camera rays).
inline float cone_width(float spread, float distance) { return spread * distance; }

// The material's values at `si`: factors times texture lookups.
SurfaceMaterial at_surface(const Material& m, const SurfaceInteraction& si, float cone_width);

// `si` with its shading normal bent by the material's normal map (unchanged without one).
void apply_normal_map(const Material& m, SurfaceInteraction& si, float cone_width);

// Alpha of the material at UV sets `uv` (finest level; every ray and structure tests the
// same texels), and whether the surface is there: always for opaque materials.
float alpha_at(const Material& m, const Vec2 uv[kUvSetCount]);
bool surface_present(const Material& m, const Vec2 uv[kUvSetCount]);

}  // namespace gilab
