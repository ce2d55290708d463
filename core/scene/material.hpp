#pragma once
// Surface description shared by every technique: a Lambertian base, an optional glossy
// lobe (normalized modified Phong), and emission. Loaders map their formats onto this.
#include <string>
#include "core/util/math.hpp"

namespace gilab {

struct Material {
    std::string name = "default";
    Vec3 albedo{0.8f};          // diffuse reflectance (baseColor, Kd)
    Vec3 specular{0.0f};        // glossy lobe reflectance (Ks); zero = pure Lambertian
    float phong_exponent = 0;   // glossy lobe sharpness (Ns); see exponent_from_roughness
    Vec3 emission{0.0f};        // emitted radiance (Ke, emissiveFactor), W/(m² sr) per channel

    bool is_emissive() const { return max_component(emission) > 0.0f; }
    bool has_glossy_lobe() const { return max_component(specular) > 0.0f && phong_exponent > 0.0f; }
};

// Roughness α (GGX-style, glTF metallicRoughness) to a Phong exponent with a similar
// lobe width: n = 2/α² − 2 (Walter et al. 2007).
inline float exponent_from_roughness(float roughness) {
    float a = std::max(roughness * roughness, 1e-3f);
    return std::max(2.0f / (a * a) - 2.0f, 0.0f);
}

}  // namespace gilab
