#pragma once
// Surface description shared by every technique: a Lambertian base, an optional glossy
// lobe (normalized modified Phong), and emission, each optionally textured, plus an
// alpha mask and a normal map. Loaders map their formats onto this; `at_surface`
// (core/render/surface_material.hpp) resolves the textures at a surface point.
#include <string>
#include <utility>
#include "core/texture/texture.hpp"
#include "core/util/math.hpp"

namespace gilab {

// Opaque, or cut out where alpha < alpha_cutoff (glTF MASK; glTF BLEND is read as MASK at
// the cutoff 0.5, so a surface is either there or not for every ray and every technique).
enum class AlphaMode { Opaque, Mask };

// The values the reflection model and the emitters read, at one surface point: a
// Material's factors, or the factors times its textures there (at_surface). Small and
// plain, so resolving a material per hit copies no name and no texture reference.
struct SurfaceMaterial {
    Vec3 albedo{0.8f};          // diffuse reflectance (baseColor, Kd)
    Vec3 specular{0.0f};        // glossy lobe reflectance (Ks); zero = pure Lambertian
    float phong_exponent = 0;   // glossy lobe sharpness (Ns); see exponent_from_roughness
    Vec3 emission{0.0f};        // emitted radiance (Ke, emissiveFactor), W/(m² sr) per channel

    bool is_emissive() const { return max_component(emission) > 0.0f; }
    bool has_glossy_lobe() const { return max_component(specular) > 0.0f && phong_exponent > 0.0f; }
};

struct Material : SurfaceMaterial {
    std::string name = "default";

    TextureRef albedo_texture;    // linear RGB multiplies albedo (baseColorTexture, map_Kd)
    TextureRef emission_texture;  // linear RGB multiplies emission (emissiveTexture, map_Ke)
    TextureRef normal_texture;    // tangent-space normal map (normalTexture, map_bump/norm)
    float normal_scale = 1.0f;    // glTF normalTexture.scale: scales the map's x and y
    AlphaMode alpha_mode = AlphaMode::Opaque;
    float alpha = 1.0f;           // baseColorFactor's alpha, d
    float alpha_cutoff = 0.5f;
    TextureRef alpha_texture;     // its alpha channel multiplies `alpha` (base colour texture, map_d)

    bool alpha_tested() const { return alpha_mode == AlphaMode::Mask; }
    bool has_textures() const {
        return albedo_texture || emission_texture || normal_texture || (alpha_tested() && alpha_texture);
    }
};

// A named Lambertian material, optionally emissive: the procedural scenes' building block.
inline Material diffuse_material(std::string name, Vec3 albedo, Vec3 emission = Vec3(0)) {
    Material m;
    m.name = std::move(name);
    m.albedo = albedo;
    m.emission = emission;
    return m;
}

// Roughness α (GGX-style, glTF metallicRoughness) to a Phong exponent with a similar
// lobe width: n = 2/α² − 2 (Walter et al. 2007).
inline float exponent_from_roughness(float roughness) {
    float a = std::max(roughness * roughness, 1e-3f);
    return std::max(2.0f / (a * a) - 2.0f, 0.0f);
}

}  // namespace gilab
