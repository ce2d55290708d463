#include "techniques/photon_mapping/primary_hit.hpp"

#include "core/render/bsdf.hpp"
#include "core/render/surface_material.hpp"

namespace gilab {

PrimaryHit primary_hit_of(SurfaceInteraction& si, const Material& m, float cone_width) {
    apply_normal_map(m, si, cone_width);
    PrimaryHit out;
    out.valid = true;
    out.point = {si.position, si.shading_normal, si.wo, si.material, at_surface(m, si, cone_width)};
    out.geometric_normal = si.geometric_normal;
    if (out.point.surface.is_emissive() && !si.back_face) out.emitted = out.point.surface.emission;
    return out;
}

void sample_direct_light(const PrimaryShadingContext& ctx, const SurfaceInteraction& si, Rng& rng,
                         std::span<LightSampleRecord> samples, PrimaryHit& hit) {
    const SurfaceMaterial& m = hit.point.surface;
    // A black surface reflects nothing whatever the samples say: skip its shadow rays.
    const bool reflects = max_component(m.albedo) > 0.0f || m.has_glossy_lobe();
    if (ctx.light_samples <= 0 || ctx.lights.empty() || !reflects) return;
    auto add = [&](const LightSample& ls, float inv_n) {
        if (!(ls.pdf > 0.0f) || is_black(ls.Li) || glm::dot(ls.wi, si.geometric_normal) <= 0.0f) return;
        const float cos_i = glm::dot(si.shading_normal, ls.wi);
        if (!(cos_i > 0.0f) || ctx.tracer.occluded(shadow_ray(si, ls))) return;
        LightSampleRecord rec{ls.wi, ls.Li * (cos_i / ls.pdf * inv_n)};
        hit.irradiance += rec.weight;
        if (hit.sample_count < samples.size() && hit.sample_count < UINT16_MAX) samples[hit.sample_count++] = rec;
    };
    const float inv_n = 1.0f / float(ctx.light_samples);
    if (!ctx.exact_punctual()) {
        for (int k = 0; k < ctx.light_samples; ++k) add(ctx.lights.sample_incident(si.position, rng), inv_n);
        return;
    }
    for (size_t i = 0; i < ctx.lights.punctual_count(); ++i) add(ctx.lights.punctual_incident(i, si.position), 1.0f);
    if (ctx.lights.has_area_lights())
        for (int k = 0; k < ctx.light_samples; ++k) add(ctx.lights.sample_area_incident(si.position, rng), inv_n);
}

Vec3 direct_radiance(const SurfaceMaterial& m, const PrimaryHit& hit, const Vec3& wo, std::span<const LightSampleRecord> samples) {
    Vec3 L = hit.emitted;
    const Vec3& n = hit.point.normal;
    if (glm::dot(n, wo) <= 0.0f) return L;  // the BSDF is zero below the shading horizon
    L += bsdf_diffuse(m) * hit.irradiance;
    if (m.has_glossy_lobe())
        for (size_t k = 0; k < hit.sample_count && k < samples.size(); ++k)
            L += bsdf_glossy(m, n, wo, samples[k].wi) * samples[k].weight;
    return L;
}

}  // namespace gilab
