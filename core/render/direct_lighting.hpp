#pragma once
// Direct lighting with Embree shadow rays, for both the voxels (light injection) and the
// visible pixels. Punctual lights (point, spot, directional) are evaluated exactly, one
// shadow ray each, so nothing flickers when the camera moves; emissive triangles are
// sampled `area_samples` times (light picked by power, stratified; point uniform on the
// triangle) from an Rng keyed by what is being lit (a world voxel face or a pixel).
// Each evaluation is a list of shadow queries (a ray and what it adds when unblocked):
// traced one by one for a pixel, or gathered over many voxel faces and traced as one
// Embree stream (RayTracer::occluded on a span) in the light injection.
#include <cstdint>
#include <vector>
#include "core/scene/light.hpp"
#include "core/render/light_sampler.hpp"
#include "core/scene/material.hpp"
#include "core/render/ray_tracer.hpp"
#include "core/util/rng.hpp"
#include "core/render/sampling.hpp"

namespace gilab {

// A shadow ray and the light it brings when nothing blocks it.
struct ShadowQuery {
    Ray ray;
    Vec3 contribution{0.0f};
};

class DirectLighting {
public:
    DirectLighting() = default;
    DirectLighting(const SceneFrame& frame, const std::vector<Material>& materials, int area_samples);

    // Irradiance E = Σ L_i cos θ_i on a surface at p with unit normal n (unoccluded
    // part only); shadow rays start at p + offset·n.
    Vec3 irradiance(const RayTracer& tracer, const Vec3& p, const Vec3& n, float offset, Rng& rng) const;
    // Reflected radiance towards wo: Σ f(wo, wi) L_i cos θ_i for material m, shading
    // normal n and geometric normal ng (both on wo's side); rays start at p + offset·ng.
    Vec3 reflected(const RayTracer& tracer, const SurfaceMaterial& m, const Vec3& p, const Vec3& n, const Vec3& ng,
                   const Vec3& wo, float offset, Rng& rng) const;

    // irradiance() as shadow queries appended to `out` (same rays, same random numbers):
    // E is the sum, in order, of the contributions of the unblocked ones.
    void irradiance_queries(const Vec3& p, const Vec3& n, float offset, Rng& rng, std::vector<ShadowQuery>& out) const;

    bool empty() const { return punctual_.empty() && triangles_.empty(); }

private:
    template <class Weight>
    void queries(const Vec3& p, const Vec3& ng, float offset, Rng& rng, Weight&& weight,
                 std::vector<ShadowQuery>& out) const;
    template <class Weight>
    Vec3 accumulate(const RayTracer& tracer, const Vec3& p, const Vec3& ng, float offset, Rng& rng,
                    Weight&& weight) const;
    std::vector<PunctualLight> punctual_;
    std::vector<EmissiveTriangle> triangles_;
    DiscreteDistribution distribution_;  // over triangles_, by power
    int area_samples_ = 1;
};

}  // namespace gilab
