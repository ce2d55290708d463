#pragma once
// Ray casting through a time-correlated multi-frame DAG (P2 §4, Table 6): prepare
// voxelizes every frame of the scene's animation into one DAG with a root per frame;
// update(t) only selects the root of the nearest frame (nothing is rebuilt per frame,
// which is the point of the structure); render casts one primary ray per pixel through
// that root, shades the hit with the entered voxel face's normal and one light (N·L plus
// a small ambient term). Visibility comes from the frame's shadow DAGs (P2 §3; built for
// every frame at prepare: one over a directional or spot light's light space, a cube of
// six for a point light) or from a shadow ray through the same frame's DAG, as the
// `shadows` setting chooses.
//
// Settings: see dag_raycast_settings.hpp. Layers: color (grey Lambertian voxels: the
// voxels carry no material), normal (the face normal; 0 for background), depth (distance
// from the eye to where the ray enters the hit voxel; 0 for background), visibility
// (1 channel: the shadow test's answer; 0 for background and surfaces facing away).
// Without a point, spot or directional light, a headlight at the eye stands in.
#include <string>
#include <vector>
#include "accel/shadow/light_shadow_dags.hpp"
#include "core/scene/light.hpp"
#include "accel/temporal/animation_dag.hpp"
#include "techniques/dag_raycast/dag_raycast_settings.hpp"
#include "techniques/technique.hpp"

namespace gilab {

class DagRaycastTechnique final : public Technique {
public:
    std::string name() const override { return "dag_raycast"; }
    void prepare(const Scene& scene, const Settings& settings) override;
    // Selects frame round(t · fps), clamped to the frames built (the scene's animation
    // clamps the same way).
    void update(double time) override;
    void render(const ViewSet& views, std::vector<Film>& films) override;
    Stats stats() const override;

    const LaidOutMultiFrameDag& dag() const { return animation_.dag; }
    size_t frame() const { return frame_; }
    size_t frame_count() const { return animation_.times.size(); }
    double fps() const { return fps_; }

private:
    bool prepared() const { return !animation_.times.empty(); }
    // The shading light of the current frame, or nullptr for the headlight.
    const PunctualLight* light() const;
    // Resolves `shadows` for the chosen light; builds every frame's shadow DAG if needed.
    void prepare_shadows(const Scene& scene);

    DagRaycastSettings settings_;
    std::string config_hash_;  // of the settings as given (film provenance)
    AnimationDag animation_;
    double fps_ = 30.0;
    int light_index_ = -1;  // into each frame's lights; -1 = headlight
    size_t frame_ = 0;
    DagShadowSource shadows_ = DagShadowSource::None;  // resolved: never Auto
    std::vector<LightShadowDags> shadow_dags_;         // one set per frame with ShadowDag
    Stats stats_;
};

void register_dag_raycast(TechniqueRegistry& registry);

}  // namespace gilab
