#pragma once
// Photon mapping as in P1: photons traced from the lights into a photon map (hash grid,
// Jensen kd-tree or nanoflann), then per pixel one primary ray, direct light by shadow
// rays (next-event estimation, `light_samples` per hit) and indirect light by density
// estimation over the photon map at the primary hit (photon_gather.hpp).
//
// Layers: color (global = direct + indirect), direct (emission seen directly + one-bounce
// lighting by shadow rays), indirect (two or more bounces: the map stores photons from
// their second surface hit on, i.e. light that has bounced at least once) — the same
// split as the path tracer's layers.
//
// Settings: photons (emitted, 256·256), radius (0.05), gather (radius | knn), k (128),
// photon_map (hash_grid | kd_tree | nanoflann), hash_query (runs9 | cells27),
// pass (fused: trace and gather per pixel in one loop | split: all primary hits into a
// buffer first, then a gather pass over the hits sorted by cell; bit-identical),
// tile_shared (false | true: hits sharing a hash cell fetch that neighbourhood once and
// are all evaluated against it; hash grid only; bit-identical), seed (1),
// light_samples (1), max_photon_depth (8: surface hits along a photon path),
// tile_size (16). Primary rays go through pixel centres.
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include "accel/hash_grid_photon_map.hpp"
#include "accel/photon_map.hpp"
#include "core/light_sampler.hpp"
#include "core/ray_tracer.hpp"
#include "techniques/photon_mapping/photon_gather.hpp"
#include "core/traced_scene.hpp"
#include "techniques/technique.hpp"

namespace gilab {

struct PhotonMappingSettings {
    uint64_t photons = 256 * 256;
    float radius = 0.05f;
    GatherMode gather = GatherMode::Radius;
    int k = 128;
    PhotonMapKind photon_map = PhotonMapKind::HashGrid;
    HashQuery hash_query = HashQuery::Runs9;
    bool split = false;
    bool tile_shared = false;
    uint64_t seed = 1;
    int light_samples = 1;
    int max_photon_depth = 8;
    int tile_size = 16;

    // Reads every key above (with get, so the caller can report the rest) and checks
    // the values; throws Error naming the bad key.
    static PhotonMappingSettings from(const Settings& settings);
};

class PhotonMappingTechnique final : public Technique {
public:
    std::string name() const override { return "photon"; }
    void prepare(const Scene& scene, const Settings& settings) override;
    void update(double time) override;
    void render(const ViewSet& views, std::vector<Film>& films) override;
    Stats stats() const override { return stats_; }

    const PhotonMappingSettings& settings() const { return settings_; }
    const PhotonMap& photon_map() const { return *map_; }

private:
    void trace_and_build();
    void render_view(const EyeCamera& camera, uint64_t view, Film& film, PhotonQueryStats& query_stats,
                     Stats& frame_stats) const;

    PhotonMappingSettings settings_;
    std::string config_hash_;
    TracedScene scene_;
    std::unique_ptr<PhotonMap> map_;
    Stats stats_;
};

void register_photon_mapping(TechniqueRegistry& registry);

}  // namespace gilab
