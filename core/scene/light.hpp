#pragma once
// Punctual lights (point, spot, directional). Area lights are emissive triangles: any
// triangle whose material has emission is a light (see LightSampler).
#include <string>
#include "core/util/math.hpp"

namespace gilab {

enum class LightType { Point, Spot, Directional };

struct PunctualLight {
    std::string name;
    LightType type = LightType::Point;
    Vec3 position{0};            // point, spot (world space after evaluation)
    Vec3 direction{0, -1, 0};    // spot and directional: direction the light travels
    // Point/spot: radiant intensity, W/sr per channel. Directional: irradiance on a
    // surface facing the light, W/m² per channel.
    Vec3 intensity{1};
    float cos_inner = 1.0f;      // spot: full intensity inside this cone
    float cos_outer = 0.0f;      // spot: zero outside this cone
    int node = -1;               // scene node the light is attached to, -1 = world
};

const char* to_string(LightType type);

// Spot falloff: 1 inside cos_inner, 0 outside cos_outer, smoothstep in cosθ between.
// The smoothstep integrates to 1/2 over its interval, so the cone's power is exactly
// 2π(1 − (cos_inner + cos_outer)/2)·I.
float spot_falloff(const PunctualLight& light, float cos_theta);

}  // namespace gilab
