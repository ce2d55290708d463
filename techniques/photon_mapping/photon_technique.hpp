#pragma once
// Photon mapping as in P1: photons traced from the lights into a photon map (hash grid,
// Jensen kd-tree or nanoflann), then per pixel one primary ray and density estimation
// over the photon map at the primary hit (photon_gather.hpp). Where direct light comes
// from depends on `photon_storage`:
// * indirect (default): the map stores photons from their second surface hit on, and
//   direct light is computed by shadow rays (next-event estimation: each punctual light
//   exactly and `light_samples` area-light samples per hit, primary_hit.hpp). Layers: direct = emission seen directly + one-bounce lighting by shadow rays;
//   indirect = the map's estimate (light that has bounced at least once).
// * every_hit (P1's photon map): a copy is stored at every non-specular hit, the first
//   one included, so the map holds one more photon for every photon that reaches a
//   surface; direct light comes from the map too, with no shadow rays or light samples at
//   the primary hit (light_samples must be left out or 0). Each stored photon records its hit index, and the estimate is
//   split by it: direct = emission seen directly + the first-hit photons' estimate;
//   indirect = the later-hit photons' estimate, the same quantity as in indirect mode.
// Either way color = direct + indirect, the same split as the path tracer's layers.
//
// Settings: PhotonMappingSettings::schema() declares every key with its default, range
// and description (`gilab list settings photon`). How the modes combine:
// * pass=split puts all primary hits into a buffer first, then a gather pass
//   (bit-identical to fused). gather_order=cell walks the hits sorted by hash cell (what
//   tile_shared=cell_groups needs); gather_order=tiles walks the share tiles in image
//   order, the paper's hybrid kernel (what tile_shared=paper needs). With
//   tile_shared=off both orders give the same image, so the paper's sharing can be timed
//   against a per-hit gather walking the same tiles.
// * tile_shared (tile_share.hpp; hash grid only; bit-identical): paper = P1's Algorithm
//   1, a share_tile × share_tile screen tile fetches its cell's neighbourhood once only
//   if all its hits lie in one hash cell, else each hit gathers alone; cell_groups = hits
//   sharing a cell share one fetch, within a render tile (fused) or across the image
//   (split, hits sorted by cell).
// * spp > 1 (pixel_samples.hpp): each primary ray has its own light samples, all gather
//   from the frame's one photon map, and every layer is the samples' mean. Tile sharing
//   and the split pass take a pixel's samples as more hits; stereo reuse and foveation
//   work per sample index (below).
//
// Stereo (a two-view render): the right eye draws its light samples from the stream of
// the left pixel that sees the same point, so both eyes show the same noise on a surface
// (no binocular rivalry from independent noise) and the stereo-reuse error below measures
// geometry, not noise. stereo_reuse fills right-eye pixels from the left eye's hits
// (stereo_reuse.hpp; stereo_match, stereo_tolerance, stereo_reshade, stereo_fill). The right
// film gets a "reused" layer (the share of the pixel's samples that came from the left
// eye; with spp > 1 sample s of the left pixels claims sample s of the right pixels); its
// unclaimed pixels gather per hit whatever tile_shared says. With photon_storage=every_hit a
// reshaded glossy pixel re-gathers both parts of the estimate for the right eye's
// direction, a Lambertian one copies the left eye's direct and indirect light.
//
// Foveation (foveation.hpp): gathers at full rate in the fovea, per 2×2 and 4×4 blocks
// beyond, over a map of every periphery_photon_stride-th photon. Needs pass=fused, tile_shared=off, photon_storage=indirect (it keeps direct light per
// pixel by shadow rays and shares only gathered indirect light) and a tile_size that is
// a multiple of 4. With stereo_reuse the right eye's unclaimed pixels are gathered at the
// full rate. With spp > 1 a block gathers once per surface for each sample index.
//
// Progressive mode (progressive.hpp; progressive_pass.cpp): `radius` is the initial
// radius. Each iteration takes one jittered visible point per pixel (drawn as sample
// `iteration` of the pixel would be with spp samples) and a fresh photon pass (photon
// pass index = iteration). Direct light is the shadow-ray estimate, so it needs
// photon_storage=indirect, and it needs photon_map=hash_grid, gather=radius, pass=fused,
// tile_shared=off, spp=1 (one visible point per iteration), and refuses stereo_reuse and
// foveated. Stereo views render without reuse, each eye with its own statistics and
// light-sample streams, sharing each iteration's photons.
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include "accel/photon/hash_grid_photon_map.hpp"
#include "accel/photon/photon_map.hpp"
#include "core/render/light_sampler.hpp"
#include "core/render/ray_tracer.hpp"
#include "techniques/photon_mapping/foveation.hpp"
#include "techniques/photon_mapping/photon_gather.hpp"
#include "techniques/photon_mapping/pixel_samples.hpp"
#include "techniques/photon_mapping/progressive.hpp"
#include "techniques/photon_mapping/stereo_reuse.hpp"
#include "techniques/photon_mapping/tile_share.hpp"
#include "core/render/traced_scene.hpp"
#include "techniques/technique.hpp"

namespace gilab {

// Which photon copies the map keeps (see the header comment).
enum class PhotonStorage { Indirect, EveryHit };
const char* to_string(PhotonStorage storage);  // "indirect", "every_hit"

struct PhotonMappingSettings {
    uint64_t photons = 256 * 256;
    // Without a `radius` setting, prepare() sets it to this fraction of the scene's
    // bounding-box diagonal (0.052 on the unit Cornell box), so that the default gathers
    // a similar share of the photons on a 1 m box and a 40 m cathedral.
    static constexpr float kRadiusPerDiagonal = 0.03f;
    float radius = 0.05f;
    bool radius_from_scene = true;  // no `radius` setting given
    GatherMode gather = GatherMode::Radius;
    int k = 128;
    PhotonMapKind photon_map = PhotonMapKind::HashGrid;
    HashQuery hash_query = HashQuery::Runs9;
    bool split = false;
    PhotonStorage storage = PhotonStorage::Indirect;
    TileShare tile_shared = TileShare::Off;
    int share_tile = 8;  // pixels square: the paper's thread-group tile (its size is not given)
    bool gather_by_tiles = false;  // pass=split: walk share tiles in image order instead of hits sorted by cell
    uint64_t seed = 1;
    int light_samples = 1;
    int max_photon_depth = 8;
    int tile_size = 16;
    PixelSampling sampling;  // spp, jitter (pixel_samples.hpp)
    StereoReuseSettings stereo;
    FoveationSettings foveation;
    ProgressiveSettings progressive;  // progressive.hpp

    // Every key with its default (the members above), range and description.
    static const SettingsSchema& schema();
    // Reads every key of the schema (with get, so the caller can report the rest) and
    // checks the values and how they combine; throws Error naming the bad key.
    static PhotonMappingSettings from(const Settings& settings);
};

class PhotonMappingTechnique final : public Technique {
public:
    PhotonMappingTechnique();
    ~PhotonMappingTechnique() override;
    std::string name() const override { return "photon"; }
    void prepare(const Scene& scene, const Settings& settings) override;
    void update(double time) override;
    void render(const ViewSet& views, std::vector<Film>& films) override;
    Stats stats() const override { return stats_; }

    const PhotonMappingSettings& settings() const { return settings_; }
    const PhotonMap& photon_map() const { return *map_; }  // not in progressive mode (no map between renders)

private:
    struct KeptHits;
    struct ViewOptions;
    void trace_and_build();
    void render_view(const EyeCamera& camera, const ViewOptions& options, Film& film, PhotonQueryStats& query_stats,
                     Stats& frame_stats) const;
    void render_right_reusing(const EyeCamera& left, const EyeCamera& right, const KeptHits& kept, Film& film,
                              PhotonQueryStats& query_stats, Stats& frame_stats) const;
    void render_progressive(const ViewSet& views, std::vector<Film>& films);  // progressive_pass.cpp

    PhotonMappingSettings settings_;
    std::string config_hash_;
    TracedScene scene_;
    std::unique_ptr<PhotonMap> map_;
    std::unique_ptr<PhotonMap> periphery_map_;  // foveation: every stride-th photon
    std::unique_ptr<KeptHits> kept_;            // stereo reuse: the left eye's hits, reused across frames
    Stats stats_;
};

void register_photon_mapping(TechniqueRegistry& registry);

}  // namespace gilab
