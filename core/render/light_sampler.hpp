#pragma once
// All lights of a scene frame (emissive triangles and punctual lights) in one
// distribution proportional to emitted power.
#include <vector>
#include "core/render/interaction.hpp"
#include "core/util/rng.hpp"
#include "core/render/sampling.hpp"
#include "core/scene/scene.hpp"

namespace gilab {

struct EmissiveTriangle {
    uint32_t mesh = 0, triangle = 0;
    Vec3 p0{0}, p1{0}, p2{0};
    Vec3 normal{0};       // unit, winding normal; emits on this side only
    float area = 0;
    Vec3 radiance{0};     // the material's emission factor
    // An emission texture multiplies the radiance at each point, looked up at the
    // finest level (a light sample has no footprint); uv0..uv2 are its UV set's corners.
    TextureRef texture;
    Vec2 uv0{0}, uv1{0}, uv2{0};

    // Emitted radiance at barycentrics b (of p1 and p2).
    Vec3 radiance_at(const Vec2& b) const;
};

// A sample of incident light at a shading point.
struct LightSample {
    Vec3 wi{0};           // unit, from the shading point towards the light
    float distance = 0;   // to the light sample (infinity for directional)
    // Solid-angle pdf for area lights (including the light-selection probability);
    // for punctual lights the selection probability alone.
    float pdf = 0;
    bool delta = false;   // punctual: cannot be hit by BSDF sampling
    // Incident radiance (area) or irradiance-like term I/d², E (punctual) arriving along
    // wi, unoccluded. The NEE estimate is f · Li · |cos θ| / pdf after a shadow test.
    Vec3 Li{0};
};

// A sample of light emission (for photon tracing).
struct EmissionSample {
    Ray ray;
    Vec3 power{0};        // flux carried by this sample / its pdf (Φ per sample before ÷N)
};

class LightSampler {
public:
    LightSampler() = default;
    // `materials` are the scene's (Scene::materials): a frame stores only material ids.
    LightSampler(const SceneFrame& frame, const std::vector<Material>& materials);

    bool empty() const { return distribution_.empty(); }
    size_t light_count() const { return distribution_.size(); }
    float total_power() const { return distribution_.total(); }

    // Next-event estimation: pick a light by power, sample a point on it.
    LightSample sample_incident(const Vec3& shading_point, Rng& rng) const;
    // The same among the emissive triangles only (pdf: their own power distribution),
    // for estimators that take every punctual light exactly (punctual_incident). With
    // no punctual light it draws the same samples as sample_incident.
    LightSample sample_area_incident(const Vec3& shading_point, Rng& rng) const;
    bool has_area_lights() const { return !triangles_.empty(); }
    // Punctual light i (0 ≤ i < punctual_count) seen from a point, with pdf 1 (0 at the
    // light's own position).
    size_t punctual_count() const { return punctual_.size(); }
    LightSample punctual_incident(size_t i, const Vec3& shading_point) const;
    // Solid-angle pdf that sample_incident would produce direction wi hitting emissive
    // triangle (mesh, triangle) at point p_light (for MIS on BSDF-sampled hits).
    float pdf_incident(const Vec3& shading_point, uint32_t mesh, uint32_t triangle,
                       const Vec3& p_light) const;
    // Photon emission: pick a light by power, sample origin and direction.
    EmissionSample sample_emission(Rng& rng) const;

    const std::vector<EmissiveTriangle>& emissive_triangles() const { return triangles_; }

private:
    std::vector<EmissiveTriangle> triangles_;
    std::vector<PunctualLight> punctual_;
    static LightSample triangle_incident(const EmissiveTriangle& e, const Vec3& x, const Vec2& u, float pmf);

    DiscreteDistribution distribution_;   // over triangles_ then punctual_
    DiscreteDistribution area_distribution_;  // over triangles_
    std::vector<int> triangle_index_of_;  // per (mesh, triangle) lookup, flattened
    std::vector<size_t> mesh_offsets_;
    Vec3 scene_center_{0};
    float scene_radius_ = 1;
};

// The shadow ray for a light sample seen from a surface, stopping just short of the
// light. It is aimed from the offset origin at the sample point itself: a ray parallel
// to wi would be shifted off the light point and could hit the emitter's own plane.
Ray shadow_ray(const SurfaceInteraction& si, const LightSample& sample);

}  // namespace gilab
