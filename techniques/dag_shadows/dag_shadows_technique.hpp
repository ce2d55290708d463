#pragma once
// Direct lighting from one light whose visibility comes from a choice of structures
// (P2 §3, Figs. 16–18): Embree shadow rays (ground truth), a plain shadow map (the
// paper's S1), the shadow DAG (S2) or the shadow DAG over double depth maps (S3). Each
// frame traces primary hits, then asks the structure for the visibility of all hit
// points in one batch (timed on its own as the frame's shadow time), then shades.
//
// Settings: DagShadowsSettings::schema() (`gilab list settings dag_shadows`).
// Layers: color (emission + diffuse reflection of the light and the ambient term),
// visibility (1 channel, the answer of the structure; 0 for background and for surfaces
// turned away from the light, which are not looked up).
#include <memory>
#include <string>
#include "accel/shadow/shadow_dag.hpp"
#include "accel/shadow/shadow_map.hpp"
#include "core/render/traced_scene.hpp"
#include "techniques/technique.hpp"

namespace gilab {

enum class VisibilitySource { Ray, ShadowMap, ShadowDag, ShadowDagDoubleDepth };
const char* to_string(VisibilitySource source);

struct DagShadowsSettings {
    VisibilitySource visibility = VisibilitySource::ShadowDag;
    uint32_t resolution = 1024;
    int light = -1;
    int pcf = 1;
    int shadow_map_bits = 32;
    uint32_t tile = 0;
    ShadowState undefined_as = ShadowState::Shadow;
    float ambient = 0.03f;
    int tile_size = 16;
    uint64_t seed = 1;  // accepted and recorded; the technique draws no random numbers
    // Every key with its default (the members above), range and description.
    static const SettingsSchema& schema();
    static DagShadowsSettings from(const Settings& settings);
};

class DagShadowsTechnique final : public Technique {
public:
    std::string name() const override { return "dag_shadows"; }
    void prepare(const Scene& scene, const Settings& settings) override;
    void update(double time) override;
    void render(const ViewSet& views, std::vector<Film>& films) override;
    Stats stats() const override;

    const ShadowDag* dag() const { return dag_.get(); }
    const ShadowMap* shadow_map() const { return map_.get(); }

private:
    void build_structure();
    const PunctualLight& light() const { return scene_.frame().lights[light_index_]; }

    DagShadowsSettings settings_;
    std::string config_hash_;  // of the settings as given (film provenance)
    const Scene* source_ = nullptr;
    TracedScene scene_;
    int light_index_ = 0;
    std::unique_ptr<ShadowDag> dag_;
    std::unique_ptr<ShadowMap> map_;
    Stats stats_;
    Stats structure_stats_;  // of the structure built last (replaced on every rebuild)
};

void register_dag_shadows(TechniqueRegistry& registry);

}  // namespace gilab
