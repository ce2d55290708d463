#pragma once
// Voxel cone tracing on cascaded voxel textures (P3), with the dense mip-mapped 3D
// texture ("original VCT", VXGI-style) as a setting of the same technique.
//
// Per frame (one render() call):
//  1. update   — cascades follow the viewer (mean of the eye positions): each level is
//                re-centred on its schedule; a moved level scrolls toroidally, its new
//                border slabs are filled from the next coarser level and then
//                re-voxelized. `update=everything` re-voxelizes every level every frame
//                (the dense texture re-voxelizes the whole grid, as VXGI does for
//                dynamic scenes; with `update=strategy` it keeps its static voxels).
//  2. injection— direct light into the V-buffer of every updated level (Embree shadow
//                rays from each voxel face), anisotropic filtering finer → coarser, then
//                the voxel bounce: 16 fixed cones per side of the voxel (its faces whose
//                normals agree) over the hemisphere of its mean normal gather the
//                V-buffer; radiance = direct + albedo/π·Σ overwrites it and is
//                filtered again (one V-buffer, as P3's one radiance texture: levels
//                the update strategy skips this frame hold direct + bounce of their
//                last update while the others gather). Pixels then see two indirect bounces
//                (temporal_bounces: the voxel bounce gathers the frames before's
//                radiance instead, one bounce more every frame).
//  3. shading  — primary visibility and direct lighting are ray traced by Embree (the
//                paper rasterizes; we are on the CPU), then per pixel 16 diffuse cones
//                (indirect diffuse + ambient occlusion) and one specular cone along the
//                mirror direction (aperture from the Phong exponent).
// Static geometry only is voxelized; meshes under an animated node are skipped (P3 does
// not write dynamic objects into the G-buffer) but are seen, lit and cast shadows
// through Embree. Emitters are not injected into the V-buffer: surfaces receive their
// light through shadow rays, and injecting it too would count it twice.
//
// Settings: VctSettings::schema() (`gilab list settings vct`). With voxel_size 0 the
// cascades and the dense texture share the finest voxel and its lattice; clip_plane is
// explained in cone_tracer.hpp.
// Layers: color = direct + indirect + specular; direct (emission seen + direct light);
// indirect (diffuse indirect); specular (glossy indirect); ao (1 channel, 1 = open);
// albedo, normal, depth. Deterministic at any thread count.
#include <memory>
#include <optional>
#include <string>
#include <vector>
#include "accel/vct/fragment_voxelizer.hpp"
#include "accel/vct/cascaded_voxel_texture.hpp"
#include "accel/vct/dense_mip_texture.hpp"
#include "core/render/ray_tracer.hpp"
#include "core/render/traced_scene.hpp"
#include "techniques/technique.hpp"
#include "techniques/vct/cone_tracer.hpp"
#include "core/render/direct_lighting.hpp"

namespace gilab {

struct VctSettings {
    enum class Structure { Cascaded, Dense };
    enum class Update { Strategy, Everything };
    enum class Schedule { Log2, Pow2, Every };

    Structure structure = Structure::Cascaded;
    int levels = 6;
    int resolution = 32;
    double voxel_size = 0;
    int dense_resolution = 128;
    bool diffuse = true;
    int diffuse_cones = 16;
    bool specular = true;
    bool second_bounce = true;
    bool bounce_per_face = false;
    bool temporal_bounces = false;
    int injection_cones = 16;
    float ao_lambda = 0.1f;
    float cone_step = 0.25f;
    float cone_offset = 1.0f;   // cone apex moved off the surface along its normal, in voxels
    float cone_start = 1.0f;    // first sample this many voxels from the apex
    bool opacity_correction = false;
    float lod_bias = 0.0f;
    bool clip_plane = true;
    bool blend_levels = false;
    float max_distance = 0;
    Update update = Update::Strategy;
    Schedule schedule = Schedule::Log2;
    int light_samples = 4;
    uint64_t seed = 1;
    int tile_size = 16;

    // Every key with its default (the members above), range and description.
    static const SettingsSchema& schema();
    static VctSettings from(const Settings& settings);  // throws Error naming the bad key
};

// Frames between updates of cascade level d = level + 1 (P3 eq. 5, f = log2 d, read as
// an update interval): log2 → max(1, ⌈log2 d⌉) (levels 1..6: 1 1 2 2 3 3), pow2 →
// 2^(d−1), every → 1. Level d is updated on frames t with t mod period = 0.
int update_period(VctSettings::Schedule schedule, int level);

class VctTechnique final : public Technique {
public:
    VctTechnique();
    ~VctTechnique() override;
    std::string name() const override { return "vct"; }
    void prepare(const Scene& scene, const Settings& settings) override;
    void update(double time) override;
    void render(const ViewSet& views, std::vector<Film>& films) override;
    Stats stats() const override { return stats_; }

    const VctSettings& settings() const { return settings_; }
    const CascadedVoxelTexture* cascade() const { return cascade_ ? &*cascade_ : nullptr; }
    const DenseMipTexture* dense() const { return dense_ ? &*dense_ : nullptr; }
    int frame_index() const { return frame_index_; }
    // Step 1 and 2 of a frame for a viewer position (render() calls it); advances the
    // frame counter. Timings go to stats "update_ms" (of which "revoxelize_ms") and
    // "injection_ms" (of which "injection_direct_ms", "injection_bounce_ms" and
    // "filter_ms", the anisotropic filtering after the direct light and after the bounce).
    void update_voxels(const Vec3& viewer);
    // The view of the final radiance buffer the pixels gather from.
    VoxelConeView radiance_view() const;

private:
    void build_static_geometry();
    void light_cascade(const std::vector<bool>& levels);
    void light_dense();
    size_t structure_bytes() const;

    VctSettings settings_;
    std::string config_hash_;
    TracedScene scene_;
    DirectLighting lighting_;
    FragmentVoxelizer voxelizer_;
    std::optional<CascadedVoxelTexture> cascade_;
    std::optional<DenseMipTexture> dense_;
    ConeSet diffuse_set_, injection_set_;
    int frame_index_ = 0;
    Stats stats_;
};

void register_vct(TechniqueRegistry& registry);

}  // namespace gilab
