#pragma once
// What the photon technique knows about a primary hit, split into the part that does not
// depend on the viewing direction (position, normal, emission, the irradiance from the
// unoccluded light samples, and the samples themselves) and the view-dependent glossy
// lobe, which is evaluated from it for any eye position. The left eye's hits are kept in
// this form so the right eye can reuse them (stereo_reuse.hpp) and re-evaluate only the
// lobe for its own direction.
#include <cstdint>
#include <span>
#include <vector>
#include "core/scene/camera.hpp"
#include "core/render/interaction.hpp"
#include "core/render/light_sampler.hpp"
#include "core/render/ray_tracer.hpp"
#include "techniques/photon_mapping/photon_gather.hpp"

namespace gilab {

// One unoccluded light sample: direction and Li·cosθ / (pdf · N) for N samples.
struct LightSampleRecord {
    Vec3 wi{0};
    Vec3 weight{0};
};

struct PrimaryHit {
    GatherPoint point;          // position, shading normal (viewer side), wo, material and its values
    Vec3 geometric_normal{0};   // viewer side
    Vec3 emitted{0};            // emission towards the viewer (front faces only)
    Vec3 irradiance{0};         // Σ LightSampleRecord::weight: the Lambertian direct term / (ρ/π)
    uint16_t sample_count = 0;  // records in the hit's light_samples-long span
    bool valid = false;
};

// Up to this many punctual lights are each taken exactly, one shadow ray apiece, and
// `light_samples` samples go to the emissive triangles alone: sampling a few point lights
// and a sun by power leaves rare, bright pixels where a weak light is picked. With more
// punctual lights every light is sampled by power.
inline constexpr size_t kExactPunctualLights = 16;

// Everything a view's hits are shaded with.
struct PrimaryShadingContext {
    const RayTracer& tracer;
    const SceneFrame& frame;
    const std::vector<Material>& materials;
    const LightSampler& lights;
    int light_samples = 1;

    bool exact_punctual() const { return lights.punctual_count() <= kExactPunctualLights; }
    // The records one hit's next-event estimation can keep (its span's size).
    size_t records_per_hit() const {
        if (light_samples <= 0) return 0;
        return size_t(light_samples) + (exact_punctual() ? lights.punctual_count() : 0);
    }
};

// The geometry of a hit and the emission the viewer sees; no lighting yet. The
// material's textures are filtered over `cone_width` (the camera ray's cone at the hit)
// and its normal map bends si's shading normal first.
PrimaryHit primary_hit_of(SurfaceInteraction& si, const Material& m, float cone_width);

// Next-event estimation at the hit: every punctual light exactly and light_samples area
// samples drawn from `rng` (or, past kExactPunctualLights, light_samples samples of all
// lights by power); the unoccluded ones summed into hit.irradiance and stored in
// `samples` (size ctx.records_per_hit()).
void sample_direct_light(const PrimaryShadingContext& ctx, const SurfaceInteraction& si, Rng& rng,
                         std::span<LightSampleRecord> samples, PrimaryHit& hit);

// Direct radiance of a hit towards a viewer in direction wo (unit, from the point):
// emission + ρ/π · irradiance + Σ glossy(wo, wi) · weight. The same arithmetic for the
// eye that traced the hit and for an eye that reuses it, so a Lambertian hit gives
// bit-identical radiance to both.
Vec3 direct_radiance(const SurfaceMaterial& m, const PrimaryHit& hit, const Vec3& wo, std::span<const LightSampleRecord> samples);

}  // namespace gilab
