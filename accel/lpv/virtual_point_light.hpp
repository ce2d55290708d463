#pragma once
// What a reflective shadow map texel becomes (Dachsbacher & Stamminger 2005, used by
// Kaplanyan & Dachsbacher 2010, §4.1): a virtual point light re-emitting the flux the
// texel's surface reflects, and a surfel for the geometry volume (§4.3).
#include "core/util/math.hpp"

namespace gilab {

// A diffuse emitter: radiant intensity I(ω) = flux/π · max(0, normal·ω).
struct VirtualPointLight {
    Vec3 position{0};
    Vec3 normal{0, 1, 0};  // unit, on the side the light came from
    Vec3 flux{0};          // reflected flux, W per channel
};

// A piece of surface that blocks light passing through its cell.
struct Surfel {
    Vec3 position{0};
    Vec3 normal{0, 1, 0};  // unit, towards whoever saw it (the light or the camera)
    float area = 0;        // world units²
};

}  // namespace gilab
