#pragma once
// Reflective shadow maps (Dachsbacher & Stamminger 2005), the light source of light
// propagation volumes (Kaplanyan & Dachsbacher 2010, §4.1). Every light is "rendered"
// from its own point of view at `size`² texels per map; we are on the CPU, so a texel is
// one Embree ray instead of a rasterized fragment. Each texel that hits a surface gives
//  · a virtual point light at the hit: position, normal (towards the light) and the flux
//    the surface reflects diffusely, albedo × the flux the texel carries; and
//  · a surfel (position, normal, the texel's footprint area) for the geometry volume.
//
// Maps per light type, and the flux Φ a texel carries:
//  directional — one orthographic map over the bounding sphere of `region` (the scene
//                inside the coarsest cascade): Φ = E · texel area;
//  point       — six cube faces (90° frusta): Φ = I · Δω_texel;
//  spot        — one frustum over its outer cone when that is at most 45° wide, else six
//                cube faces; Φ = I · falloff · Δω_texel;
//  emissive triangles — sampled, not refused: one map of `size`² texels shared by all
//                emitters, each texel a spot-like emitter: a triangle picked by power
//                (stratified), a uniform point on it and a cosine-distributed direction
//                around its normal; Φ = π·A·L / (pmf · texels), so the map carries the
//                emitters' whole flux. Deterministic: the samples are keyed by texel.
#include <cstdint>
#include <string>
#include <vector>
#include "accel/lpv/virtual_point_light.hpp"
#include "core/render/traced_scene.hpp"

namespace gilab {

struct RsmOptions {
    int size = 64;         // texels per side of each map
    Bounds3 region;        // what a directional light's map must cover
    uint64_t seed = 1;     // of the emissive-triangle samples
};

// The maps of one light (several for a point light's cube). Surfels of one light never
// overlap, so the geometry volume takes them as one buffer.
struct ReflectiveShadowMap {
    std::string light;                        // the light's name, or "emissive triangles"
    std::vector<VirtualPointLight> vpls;      // texels that hit a surface, in texel order
    std::vector<Surfel> surfels;              // the same texels as surfels
    size_t texels = 0;                        // rays cast
};

// One map set per punctual light with intensity, and one for all emissive triangles
// when there are any. Deterministic at any thread count.
std::vector<ReflectiveShadowMap> render_reflective_shadow_maps(const TracedScene& scene, const RsmOptions& options);

}  // namespace gilab
