#pragma once
// The surfaces a view sees — one primary ray through each pixel centre — and their
// ray-traced direct light: the screen-space pass the real-time techniques (vct, lpv)
// share before each adds its own indirect light.
#include <cstdint>
#include <vector>
#include "core/image/film.hpp"
#include "core/render/direct_lighting.hpp"
#include "core/render/traced_scene.hpp"
#include "core/scene/camera.hpp"

namespace gilab {

struct PixelHit {
    bool hit = false;
    bool emissive_front = false;  // the front of an emitter: its emission is seen
    Vec3 position{0}, normal{0}, geometric_normal{0}, wo{0};
    uint32_t material = 0;
    SurfaceMaterial surface;  // the material with its textures looked up over the pixel's cone
    float depth = 0;  // distance along the ray
};

// One hit per pixel, row by row, in screen tiles of `tile_size`. Textures are filtered
// over the pixel's ray cone and normal maps bend `normal`.
std::vector<PixelHit> trace_visible_surfaces(const TracedScene& scene, const EyeCamera& camera, int tile_size);

// Writes the film's layers "direct" (direct light by shadow rays, plus the emission of
// emitters seen from the front), "albedo" (diffuse + specular), "normal" and "depth" for
// the hits; pixels without a hit keep what the film holds. The light samples of pixel i
// of view `view` come from Rng::for_sample(seed, i, 0, view).
void shade_direct_light(const TracedScene& scene, const DirectLighting& lighting, const std::vector<PixelHit>& hits,
                        uint64_t seed, size_t view, int tile_size, Film& film);

}  // namespace gilab
