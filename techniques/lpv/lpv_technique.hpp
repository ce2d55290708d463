#pragma once
// Cascaded light propagation volumes (Kaplanyan & Dachsbacher, "Cascaded Light
// Propagation Volumes for Real-Time Indirect Illumination", I3D 2010).
//
// Per frame (one render() call):
//  1. primary  — Embree primary rays of every view; their hits are both the pixels to
//                shade and surfels of the geometry volume (the paper's camera G-buffer).
//  2. rsm      — the cascades are re-centred on the viewer (the mean of the eyes: the
//                stereo midpoint), then a reflective shadow map per light is traced
//                (reflective_shadow_maps.hpp): VPLs and surfels.
//  3. inject   — per cascade: the geometry volume from the surfels (one buffer per light
//                and per view, merged by maximum; geometry_volume.hpp) and the VPLs as
//                clamped-cosine SH lobes (light_propagation_volume.hpp).
//  4. propagate— `iterations` gathering steps per cascade, fuzzy occlusion from the
//                second on; the steps are accumulated.
//  5. shading  — direct light by Embree shadow rays (DirectLighting, shared with vct) and
//                indirect diffuse = albedo/π · E, E from a trilinear SH lookup in the
//                finest cascade containing the point, moved `dampening` cells along the
//                normal, blended with the next cascade at its border (lpv_cascades.hpp).
// Only diffuse indirect light is carried (one bounce: VPLs are lit by the lights
// directly); emitters seen by the camera add their emission to `direct`.
//
// Settings: LpvSettings::schema() (`gilab list settings lpv`).
// Layers: color = direct + indirect; direct (emission seen + direct light); indirect;
// albedo, normal, depth. Deterministic at any thread count: every sum over VPLs or
// surfels runs in a fixed order, parallel loops write disjoint cells or pixels.
#include <memory>
#include <optional>
#include <string>
#include <vector>
#include "accel/lpv/lpv_cascades.hpp"
#include "core/render/traced_scene.hpp"
#include "techniques/lpv/lpv_settings.hpp"
#include "techniques/lpv/reflective_shadow_maps.hpp"
#include "techniques/technique.hpp"
#include "core/render/direct_lighting.hpp"
#include "core/render/visible_surfaces.hpp"

namespace gilab {

class LpvTechnique final : public Technique {
public:
    std::string name() const override { return "lpv"; }
    void prepare(const Scene& scene, const Settings& settings) override;
    void update(double time) override;
    void render(const ViewSet& views, std::vector<Film>& films) override;
    Stats stats() const override { return stats_; }

    const LpvSettings& settings() const { return settings_; }
    const LpvCascades& cascades() const { return *cascades_; }

private:
    // Steps 2–4 for a viewer position and the views' surfels.
    void update_volumes(const Vec3& viewer, const std::vector<std::vector<Surfel>>& camera_surfels);
    // The surfels of a view's hits for the geometry volume: each pixel's footprint on its surface.
    static std::vector<Surfel> camera_surfels(const EyeCamera& camera, const std::vector<PixelHit>& hits);
    size_t structure_bytes() const;

    LpvSettings settings_;
    std::string config_hash_;
    TracedScene scene_;
    DirectLighting lighting_;
    std::optional<LpvCascades> cascades_;
    std::vector<GeometryVolume> scratch_;       // one per cascade: a surfel buffer before the merge
    std::vector<ReflectiveShadowMap> maps_;     // this frame's RSMs
    std::vector<VirtualPointLight> vpls_;       // all maps' VPLs, in map order
    Stats stats_;
};

void register_lpv(TechniqueRegistry& registry);

}  // namespace gilab
