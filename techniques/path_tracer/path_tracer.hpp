#pragma once
// The reference: unidirectional path tracing with next-event estimation. Area lights
// (emissive triangles) are reached by both light sampling and BSDF sampling, combined by
// multiple importance sampling (power heuristic); punctual lights only by light sampling.
// Paths are cut by Russian roulette after `rr_depth` bounces and at `max_depth` bounces.
// Every sample draws from Rng::for_sample(seed, pixel, sample, view), and each pixel is
// accumulated by one task in sample order, so images are identical at any thread count.
//
// Settings: PathTracerSettings::schema() (`gilab list settings path`).
// Layers: color, direct (emission seen directly + one-bounce lighting), indirect
// (two or more bounces; color = direct + indirect), albedo (diffuse + specular
// reflectance at the first hit), normal (world-space shading normal at the first hit),
// depth (distance from the eye to the first hit; 0 for misses). Samples whose value is
// not finite are dropped and counted in stats "nonfinite_samples".
#include <cstdint>
#include <string>
#include "core/render/traced_scene.hpp"
#include "techniques/technique.hpp"

namespace gilab {

struct PathTracerSettings {
    int spp = 16;
    uint64_t seed = 1;
    int max_depth = 8;    // maximum number of bounces (scattering events) on a path
    int rr_depth = 3;     // Russian roulette once a path has this many bounces
    int tile_size = 16;
    bool jitter = true;

    // Every key with its default (the members above), range and description.
    static const SettingsSchema& schema();
    // Reads every key of the schema from `settings` (with get, so the caller can report
    // the rest) and checks the values; throws Error naming the bad key.
    static PathTracerSettings from(const Settings& settings);
};

class PathTracer final : public Technique {
public:
    std::string name() const override { return "path"; }
    void prepare(const Scene& scene, const Settings& settings) override;
    void update(double time) override;
    void render(const ViewSet& views, std::vector<Film>& films) override;
    Stats stats() const override { return stats_; }

    const PathTracerSettings& settings() const { return settings_; }

private:
    PathTracerSettings settings_;
    std::string config_hash_;
    TracedScene scene_;
    Stats stats_;
};

void register_path_tracer(TechniqueRegistry& registry);

}  // namespace gilab
