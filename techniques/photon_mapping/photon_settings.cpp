#include <cmath>
#include "core/util/error.hpp"
#include "core/util/format.hpp"
#include "core/util/memory_budget.hpp"
#include "techniques/photon_mapping/photon_technique.hpp"

namespace gilab {

const char* to_string(PhotonStorage storage) { return storage == PhotonStorage::EveryHit ? "every_hit" : "indirect"; }

namespace {

// Checks the progressive keys, and what progressive mode refuses (the strings are the
// values as given, for the messages).
void check_progressive(const Settings& s, PhotonMappingSettings& p, const std::string& pass, const std::string& map,
                       const std::string& gather, const std::string& storage) {
    const std::string& where = s.context();
    ProgressiveSettings& g = p.progressive;
    if (g.iterations < 1)
        throw Error(where, "setting 'iterations' must be at least 1, got " + std::to_string(g.iterations));
    if (!(g.alpha > 0.0 && g.alpha < 1.0))
        throw Error(where, "setting 'alpha' must be in (0, 1) (the fraction of new photons kept), got " +
                               format_number(g.alpha));
    if (g.time_budget && !(*g.time_budget > 0.0))
        throw Error(where, "setting 'time_budget' must be a positive number of seconds, got " +
                               format_number(*g.time_budget));
    if (!g.enabled) {
        for (const char* key : {"iterations", "alpha", "time_budget"})
            if (s.has(key))
                throw Error(where, std::string("setting '") + key + "' needs progressive=true" +
                                       (std::string(key) == "time_budget" ? " (gilab render --time-budget sets it)" : ""));
        return;
    }
    const std::string needs = "setting 'progressive' ";
    if (p.stereo.enabled)
        throw Error(where, needs + "cannot be combined with 'stereo_reuse' (progressive mode keeps per-pixel statistics "
                                   "for each eye; set stereo_reuse=false)");
    if (p.foveation.enabled)
        throw Error(where, needs + "cannot be combined with 'foveated' (every pixel keeps its own radius; set foveated=false)");
    if (p.storage != PhotonStorage::Indirect)
        throw Error(where, needs + "needs photon_storage=indirect (direct light by shadow rays, averaged over the "
                                   "iterations), got photon_storage=" + storage);
    if (p.gather != GatherMode::Radius)
        throw Error(where, needs + "needs gather=radius (each pixel gathers within its own radius), got gather=" + gather);
    if (p.photon_map != PhotonMapKind::HashGrid)
        throw Error(where, needs + "needs photon_map=hash_grid (rebuilt every iteration), got photon_map=" + map);
    if (p.split) throw Error(where, needs + "needs pass=fused, got pass=" + pass);
    if (p.tile_shared != TileShare::Off)
        throw Error(where, needs + "needs tile_shared=off (pixels gather within different radii)");
    if (p.sampling.spp != 1)
        throw Error(where, needs + "takes one visible point per pixel per iteration: leave 'spp' out (or 1) and raise "
                                   "'iterations', got spp=" + std::to_string(p.sampling.spp));
    if (s.has("jitter") && !p.sampling.jitter)
        throw Error(where, needs + "jitters every iteration's visible point; leave 'jitter' out or set it true");
    p.sampling.jitter = true;
}

}  // namespace

PhotonMappingSettings PhotonMappingSettings::from(const Settings& s) {
    PhotonMappingSettings p;
    const std::string& where = s.context();
    int64_t photons = s.get<int64_t>("photons", int64_t(p.photons));
    p.radius = s.get<float>("radius", p.radius);
    p.radius_from_scene = !s.has("radius");
    std::string gather = s.get<std::string>("gather", "radius");
    p.k = s.get<int>("k", p.k);
    std::string map = s.get<std::string>("photon_map", to_string(p.photon_map));
    std::string hash_query = s.get<std::string>("hash_query", to_string(p.hash_query));
    std::string pass = s.get<std::string>("pass", "fused");
    std::string storage = s.get<std::string>("photon_storage", to_string(p.storage));
    p.tile_shared = parse_tile_share(s.get<nlohmann::json>("tile_shared", to_string(p.tile_shared)), where);
    p.share_tile = s.get<int>("share_tile", p.share_tile);
    const bool order_given = s.has("gather_order");
    std::string order = s.get<std::string>("gather_order", p.tile_shared == TileShare::Paper ? "tiles" : "cell");
    int64_t seed = s.get<int64_t>("seed", int64_t(p.seed));
    p.light_samples = s.get<int>("light_samples", p.light_samples);
    p.max_photon_depth = s.get<int>("max_photon_depth", p.max_photon_depth);
    p.tile_size = s.get<int>("tile_size", p.tile_size);
    p.sampling.spp = s.get<int>("spp", p.sampling.spp);
    // Jittered by default only with several samples: one sample stays at the pixel centre,
    // the image of the one-ray-per-pixel technique.
    p.sampling.jitter = s.get<bool>("jitter", p.sampling.spp > 1);
    p.stereo.enabled = s.get<bool>("stereo_reuse", p.stereo.enabled);
    std::string match = s.get<std::string>("stereo_match", to_string(p.stereo.match));
    p.stereo.tolerance = s.get<float>("stereo_tolerance", p.stereo.tolerance);
    p.stereo.reshade = s.get<bool>("stereo_reshade", p.stereo.reshade);
    p.stereo.fill = s.get<bool>("stereo_fill", p.stereo.fill);
    p.foveation.enabled = s.get<bool>("foveated", p.foveation.enabled);
    p.foveation.fovea_degrees = s.get<float>("fovea_angle", p.foveation.fovea_degrees);
    p.foveation.periphery_photon_stride = s.get<int>("periphery_photon_stride", p.foveation.periphery_photon_stride);
    p.foveation.gaze_yaw_degrees = s.get<float>("gaze_yaw", p.foveation.gaze_yaw_degrees);
    p.foveation.gaze_pitch_degrees = s.get<float>("gaze_pitch", p.foveation.gaze_pitch_degrees);
    p.progressive.enabled = s.get<bool>("progressive", p.progressive.enabled);
    p.progressive.iterations = s.get<int>("iterations", p.progressive.iterations);
    p.progressive.alpha = s.get<double>("alpha", p.progressive.alpha);
    const double time_budget = s.get<double>("time_budget", 0.0);
    if (s.has("time_budget")) p.progressive.time_budget = time_budget;

    if (photons < 1) throw Error(where, "setting 'photons' must be at least 1, got " + std::to_string(photons));
    p.photons = uint64_t(photons);
    // The least a map can hold is about one stored copy per emitted photon (a closed
    // scene stores at least that): its record and its structure-of-arrays copy. A count
    // that cannot fit is refused before any photon is traced.
    constexpr uint64_t kBytesPerStoredPhoton = sizeof(Photon) + 10 * sizeof(float);
    MemoryBudget::check(MemoryBudget::times(p.photons, kBytesPerStoredPhoton),
                        "setting 'photons' = " + std::to_string(p.photons) + " (about " +
                            std::to_string(kBytesPerStoredPhoton) + " B per stored photon, one per emitted photon at least)",
                        where);
    if (!(p.radius > 0.0f) || !std::isfinite(p.radius))
        throw Error(where, "setting 'radius' must be positive and finite, got " + format_number(p.radius));
    if (gather == "radius")
        p.gather = GatherMode::Radius;
    else if (gather == "knn")
        p.gather = GatherMode::Knn;
    else
        throw Error(where, "setting 'gather' must be 'radius' or 'knn', got '" + gather + "'");
    if (p.k < 1) throw Error(where, "setting 'k' must be at least 1, got " + std::to_string(p.k));
    p.photon_map = parse_photon_map_kind(map, where + ": setting 'photon_map'");
    p.hash_query = parse_hash_query(hash_query, where + ": setting 'hash_query'");
    if (pass == "fused")
        p.split = false;
    else if (pass == "split")
        p.split = true;
    else
        throw Error(where, "setting 'pass' must be 'fused' or 'split', got '" + pass + "'");
    if (storage == "indirect")
        p.storage = PhotonStorage::Indirect;
    else if (storage == "every_hit")
        p.storage = PhotonStorage::EveryHit;
    else
        throw Error(where, "setting 'photon_storage' must be 'indirect' or 'every_hit', got '" + storage + "'");
    const bool shared = p.tile_shared != TileShare::Off;
    if (shared && p.photon_map != PhotonMapKind::HashGrid)
        throw Error(where, "setting 'tile_shared' needs photon_map=hash_grid (it shares hash-grid cells), got " + map);
    if (p.share_tile < 1)
        throw Error(where, "setting 'share_tile' must be at least 1 pixel, got " + std::to_string(p.share_tile));
    if (order != "cell" && order != "tiles")
        throw Error(where, "setting 'gather_order' must be 'cell' or 'tiles', got '" + order + "'");
    p.gather_by_tiles = order == "tiles";
    if (order_given && !p.split)
        throw Error(where, "setting 'gather_order' orders the gather pass of pass=split; got pass=" + pass);
    if (p.tile_shared == TileShare::Paper && !p.gather_by_tiles)
        throw Error(where, "setting 'tile_shared=paper' shares per screen tile, so it needs gather_order=tiles");
    if (p.tile_shared == TileShare::CellGroups && p.gather_by_tiles)
        throw Error(where, "setting 'tile_shared=cell_groups' groups hits sorted by cell, so it needs gather_order=cell");
    if (seed < 0) throw Error(where, "setting 'seed' must not be negative, got " + std::to_string(seed));
    p.seed = uint64_t(seed);
    if (p.light_samples < 0)
        throw Error(where, "setting 'light_samples' must not be negative, got " + std::to_string(p.light_samples));
    if (p.max_photon_depth < 1)
        throw Error(where, "setting 'max_photon_depth' must be at least 1, got " + std::to_string(p.max_photon_depth));
    if (p.tile_size < 1) throw Error(where, "setting 'tile_size' must be at least 1, got " + std::to_string(p.tile_size));
    if (p.sampling.spp < 1) throw Error(where, "setting 'spp' must be at least 1, got " + std::to_string(p.sampling.spp));
    if (p.sampling.spp > kMaxPhotonSpp)
        throw Error(where, "setting 'spp' must be at most " + std::to_string(kMaxPhotonSpp) + ", got " +
                               std::to_string(p.sampling.spp));
    if ((p.tile_shared == TileShare::Paper || p.gather_by_tiles) && p.tile_size % p.share_tile != 0)
        throw Error(where, "setting 'tile_shared=paper' needs a tile_size that is a multiple of share_tile (share tiles "
                           "nest in render tiles), got tile_size " + std::to_string(p.tile_size) + " and share_tile " +
                               std::to_string(p.share_tile));
    if (match == "nearest")
        p.stereo.match = StereoMatch::Nearest;
    else if (match == "strict")
        p.stereo.match = StereoMatch::Strict;
    else
        throw Error(where, "setting 'stereo_match' must be 'nearest' or 'strict', got '" + match + "'");
    if (!(p.stereo.tolerance >= 0.0f) || !std::isfinite(p.stereo.tolerance))
        throw Error(where, "setting 'stereo_tolerance' must be a finite number of pixels ≥ 0, got " + format_number(p.stereo.tolerance));
    if (p.light_samples > 0xffff)
        throw Error(where, "setting 'light_samples' must be at most 65535, got " + std::to_string(p.light_samples));
    if (p.foveation.enabled) {
        const float angle = p.foveation.fovea_degrees;
        if (!(angle > 0.0f && angle < 180.0f))
            throw Error(where, "setting 'fovea_angle' must be in (0, 180) degrees, got " + format_number(angle));
        for (auto [key, value] : {std::pair{"gaze_yaw", p.foveation.gaze_yaw_degrees},
                                  std::pair{"gaze_pitch", p.foveation.gaze_pitch_degrees}})
            if (!(std::abs(value) <= 90.0f))
                throw Error(where, std::string("setting '") + key + "' must be within ±90 degrees, got " + format_number(value));
        if (p.foveation.periphery_photon_stride < 1)
            throw Error(where, "setting 'periphery_photon_stride' must be at least 1, got " +
                                   std::to_string(p.foveation.periphery_photon_stride));
        if (p.split || shared)
            throw Error(where, "setting 'foveated' needs pass=fused and tile_shared=off (it picks the shading rate per block)");
        if (p.storage == PhotonStorage::EveryHit)
            throw Error(where, "setting 'foveated' needs photon_storage=indirect (it keeps direct light per pixel by "
                               "shadow rays and shares only the gathered indirect light within a block)");
        if (p.tile_size % 4 != 0)
            throw Error(where, "setting 'foveated' needs a tile_size that is a multiple of 4 (4×4 shading blocks), got " +
                                   std::to_string(p.tile_size));
    }
    if (p.storage == PhotonStorage::EveryHit) {
        // Direct light comes from the map: no shadow rays at the primary hit.
        if (p.light_samples != 0 && s.has("light_samples"))
            throw Error(where, "setting 'light_samples' has no effect with photon_storage=every_hit (direct light comes "
                               "from the photon map); leave it out or set 0, got " + std::to_string(p.light_samples));
        p.light_samples = 0;
    }
    if (p.stereo.fill && p.stereo.match != StereoMatch::Nearest) {
        throw Error(where, "setting 'stereo_fill' needs stereo_match=nearest (strict mode reuses only exact matches)");
    }
    check_progressive(s, p, pass, map, gather, storage);
    return p;
}

}  // namespace gilab
