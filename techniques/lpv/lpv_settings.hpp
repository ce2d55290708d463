#pragma once
// The settings of the `lpv` technique (`gilab list settings lpv`), with their defaults
// from the paper (Kaplanyan & Dachsbacher 2010): 3 cascades of 32³ cells, 8 propagation
// iterations (the paper's choice for 32³ grids: light travels 8 cells per cascade).
#include <cstdint>
#include "core/util/settings.hpp"
#include "core/util/settings_schema.hpp"

namespace gilab {

struct LpvSettings {
    int cascades = 3;
    int resolution = 32;       // cells per axis of every cascade, even
    double cell_size = 0;      // finest cascade's cell; 0: derived from the scene
    int rsm_size = 64;         // texels per side of every reflective shadow map
    int iterations = 8;        // propagation steps per cascade
    bool occlusion = true;     // fuzzy occlusion by the geometry volume
    float dampening = 0.5f;    // lookup moved this many cells along the normal
    bool gradient_dampening = true;   // light growing into the surface is scaled down
    int light_samples = 4;     // area-light samples of the ray-traced direct light
    uint64_t seed = 1;
    int tile_size = 16;

    static const SettingsSchema& schema();
    static LpvSettings from(const Settings& settings);  // throws Error naming the bad key
};

}  // namespace gilab
