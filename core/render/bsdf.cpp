#include "core/render/bsdf.hpp"

#include <cmath>
#include "core/render/sampling.hpp"

// Energy: the Lambertian term reflects at most ρ_d and the normalized Phong lobe at most
// ρ_s (exactly ρ_s at normal incidence, less when part of the lobe falls below the
// horizon), so the model conserves energy per channel only when ρ_d + ρ_s ≤ 1.
// Materials are not clamped here; loaders and scene authors are responsible for that.

namespace gilab {

namespace {

// Probability of sampling the glossy lobe: proportional to the lobes' peak reflectance.
float glossy_probability(const SurfaceMaterial& m) {
    if (!m.has_glossy_lobe()) return 0.0f;
    float d = max_component(m.albedo), s = max_component(m.specular);
    return d + s > 0.0f ? s / (d + s) : 0.0f;
}

// cos α between the mirror direction of wo and wi; symmetric in wo and wi.
float cos_alpha(const Vec3& n, const Vec3& wo, const Vec3& wi) {
    return 2.0f * glm::dot(n, wo) * glm::dot(n, wi) - glm::dot(wo, wi);
}

float phong_lobe_pdf(float cos_a, float exponent) {
    return cos_a > 0.0f ? (exponent + 1.0f) * (0.5f * kInvPi) * std::pow(cos_a, exponent) : 0.0f;
}

}  // namespace

Vec3 bsdf_eval(const SurfaceMaterial& m, const Vec3& n, const Vec3& wo, const Vec3& wi) {
    if (glm::dot(n, wo) <= 0.0f || glm::dot(n, wi) <= 0.0f) return Vec3(0.0f);
    return m.albedo * kInvPi + bsdf_glossy(m, n, wo, wi);
}

Vec3 bsdf_glossy(const SurfaceMaterial& m, const Vec3& n, const Vec3& wo, const Vec3& wi) {
    if (!m.has_glossy_lobe() || glm::dot(n, wo) <= 0.0f || glm::dot(n, wi) <= 0.0f) return Vec3(0.0f);
    float ca = cos_alpha(n, wo, wi);
    if (!(ca > 0.0f)) return Vec3(0.0f);
    return m.specular * ((m.phong_exponent + 2.0f) * (0.5f * kInvPi) * std::pow(ca, m.phong_exponent));
}

float bsdf_pdf(const SurfaceMaterial& m, const Vec3& n, const Vec3& wo, const Vec3& wi) {
    float cos_o = glm::dot(n, wo), cos_i = glm::dot(n, wi);
    if (cos_o <= 0.0f || cos_i <= 0.0f) return 0.0f;
    float ps = glossy_probability(m);
    float pdf = (1.0f - ps) * cos_i * kInvPi;
    if (ps > 0.0f) pdf += ps * phong_lobe_pdf(cos_alpha(n, wo, wi), m.phong_exponent);
    return pdf;
}

BsdfSample bsdf_sample(const SurfaceMaterial& m, const Vec3& n, const Vec3& wo, Rng& rng) {
    BsdfSample s;
    float choice = rng.uniform();
    Vec2 u = rng.uniform2();
    if (glm::dot(n, wo) <= 0.0f) return s;
    if (max_component(m.albedo) <= 0.0f && !m.has_glossy_lobe()) return s;  // black: absorbs all
    float ps = glossy_probability(m);
    if (choice < ps) {
        Vec3 mirror = 2.0f * glm::dot(n, wo) * n - wo;
        s.wi = Frame(glm::normalize(mirror)).to_world(sample_phong_lobe(u, m.phong_exponent));
    } else {
        s.wi = Frame(n).to_world(sample_cosine_hemisphere(u));
    }
    s.wi = glm::normalize(s.wi);
    float cos_i = glm::dot(n, s.wi);
    if (cos_i <= 0.0f) return s;  // glossy lobe below the horizon: the sample is lost
    s.pdf = bsdf_pdf(m, n, wo, s.wi);
    if (!(s.pdf > 0.0f)) return s;
    s.weight = bsdf_eval(m, n, wo, s.wi) * cos_i / s.pdf;
    s.valid = is_finite(s.weight);
    return s;
}

}  // namespace gilab
