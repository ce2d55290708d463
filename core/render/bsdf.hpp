#pragma once
// The shared reflection model: Lambertian + normalized modified Phong lobe
// f = ρ_d/π + ρ_s (n+2)/(2π) cos^n α, α the angle between the mirror direction and wi.
// All directions are world-space unit vectors; n is the shading normal on wo's side.
#include "core/scene/material.hpp"
#include "core/util/rng.hpp"

namespace gilab {

struct BsdfSample {
    Vec3 wi{0};
    Vec3 weight{0};   // f · cosθ / pdf
    float pdf = 0;
    bool valid = false;
};

Vec3 bsdf_eval(const SurfaceMaterial& m, const Vec3& n, const Vec3& wo, const Vec3& wi);  // f (no cos)
float bsdf_pdf(const SurfaceMaterial& m, const Vec3& n, const Vec3& wo, const Vec3& wi);
BsdfSample bsdf_sample(const SurfaceMaterial& m, const Vec3& n, const Vec3& wo, Rng& rng);
// Only the view-independent (Lambertian) part, ρ_d/π.
inline Vec3 bsdf_diffuse(const SurfaceMaterial& m) { return m.albedo * kInvPi; }
// Only the view-dependent glossy lobe (zero when either direction is below the surface);
// bsdf_eval = bsdf_diffuse + bsdf_glossy above the surface.
Vec3 bsdf_glossy(const SurfaceMaterial& m, const Vec3& n, const Vec3& wo, const Vec3& wi);

}  // namespace gilab
