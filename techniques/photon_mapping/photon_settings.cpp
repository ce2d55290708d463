#include <cmath>
#include <optional>
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
    const ProgressiveSettings& g = p.progressive;
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

const SettingsSchema& PhotonMappingSettings::schema() {
    static const SettingsSchema schema = [] {
        const PhotonMappingSettings d;
        SettingsSchema s("photon", "photon mapping (P1)");
        s.integer("photons", int64_t(d.photons)).at_least(1).unit("emitted per frame")
            .doc("Photons traced from the lights each frame (each pass in progressive mode).")
            .quality_knob(1024, 1 << 26);
        s.number("radius", d.radius).above(0).unit("scene units")
            .derived("3 % of the scene's bounding-box diagonal (the stat `radius` gives the value used)")
            .doc("Gather radius; in progressive mode every pixel's initial radius.");
        s.choice("gather", "radius", {"radius", "knn"})
            .doc("radius: every photon within the radius, no heap | knn: the k nearest, with a heap.");
        s.integer("k", d.k).at_least(1).unit("photons").doc("Photons gathered with gather=knn.");
        s.choice("photon_map", to_string(d.photon_map), {"hash_grid", "kd_tree", "nanoflann"})
            .doc("The photon map's structure: P1's hash grid, Jensen's kd-tree or a nanoflann kd-tree.");
        s.choice("hash_query", to_string(d.hash_query), {"runs9", "cells27"})
            .doc("Hash-grid neighbourhood fetch: 9 runs of 3 cells, or 27 single cells.");
        s.choice("photon_storage", to_string(d.storage), {"indirect", "every_hit"})
            .doc("indirect: photons from their second hit on, direct light by shadow rays | every_hit: P1's map, a "
                 "copy at every non-specular hit, direct light from the first-hit photons.");
        s.choice("pass", "fused", {"fused", "split"})
            .doc("fused: trace and gather per pixel in one loop | split: all primary hits into a buffer, then a "
                 "gather pass (bit-identical).");
        s.choice("gather_order", "cell", {"cell", "tiles"})
            .derived("tiles with tile_shared=paper, else cell")
            .doc("pass=split only: the gather pass walks hits sorted by hash cell, or share tiles in image order "
                 "(the paper's hybrid kernel).");
        s.choice("tile_shared", to_string(d.tile_shared), {"off", "paper", "cell_groups"})
            .booleans_mean("cell_groups", "off")
            .doc("Hash grid only, bit-identical. paper: P1's Algorithm 1, a share tile fetches its cell's "
                 "neighbourhood once if all its hits lie in one cell | cell_groups: hits sharing a cell share one "
                 "fetch. JSON true/false of older files mean cell_groups/off.");
        s.integer("share_tile", d.share_tile).at_least(1).unit("pixels square")
            .doc("The paper's thread-group tile (its size is not given); tile_size must be a multiple of it with "
                 "tile_shared=paper.");
        s.integer("seed", int64_t(d.seed)).at_least(0).doc("Seed of every random stream (same seed, same image).");
        s.integer("light_samples", d.light_samples).range(0, 0xffff).unit("per hit")
            .doc("Area-light samples per primary hit (each punctual light gets one exact shadow ray); leave out "
                 "with photon_storage=every_hit.");
        s.integer("max_photon_depth", d.max_photon_depth).at_least(1).unit("surface hits")
            .doc("Longest photon path.");
        s.integer("tile_size", d.tile_size).at_least(1).unit("pixels").doc("Square screen tile of one parallel task.");
        s.integer("spp", d.sampling.spp).range(1, kMaxPhotonSpp).unit("samples per pixel")
            .doc("Primary rays per pixel, each with its own light samples, all gathering from the frame's one map; "
                 "every layer is their mean.");
        s.boolean("jitter", false).derived("true when spp > 1")
            .doc("true: sample positions uniform in the pixel | false: pixel centres.");
        s.boolean("stereo_reuse", d.stereo.enabled)
            .doc("Stereo: fill right-eye pixels from the left eye's hits (P1's reprojection).");
        s.choice("stereo_match", to_string(d.stereo.match), {"nearest", "strict"})
            .doc("nearest: the paper's claim | strict: only where the right pixel's own ray hits the same point.");
        s.number("stereo_tolerance", d.stereo.tolerance).at_least(0).unit("pixel footprints")
            .doc("stereo_match=strict: how far the two hits may lie apart.");
        s.boolean("stereo_reshade", d.stereo.reshade)
            .doc("true: re-evaluate the glossy lobe for the right eye | false: copy the left colour (the paper).");
        s.boolean("stereo_fill", d.stereo.fill)
            .doc("Fill one-pixel reprojection cracks from neighbouring claims (stereo_match=nearest only).");
        s.boolean("foveated", d.foveation.enabled)
            .doc("Gather at every pixel in the fovea, once per 2×2 block out to twice its angle, once per 4×4 "
                 "block beyond.");
        s.number("fovea_angle", d.foveation.fovea_degrees).above(0).below(180).unit("degrees")
            .doc("Half-angle of the fovea around the gaze.");
        s.integer("periphery_photon_stride", d.foveation.periphery_photon_stride).at_least(1)
            .doc("The periphery gathers from every stride-th photon, its flux scaled up.");
        s.number("gaze_yaw", d.foveation.gaze_yaw_degrees).range(-90, 90).unit("degrees")
            .doc("Gaze turned right of the eye's forward axis.");
        s.number("gaze_pitch", d.foveation.gaze_pitch_degrees).range(-90, 90).unit("degrees")
            .doc("Gaze turned up from the eye's forward axis.");
        s.boolean("progressive", d.progressive.enabled)
            .doc("Stochastic progressive photon mapping (Hachisuka & Jensen 2009).");
        s.integer("iterations", d.progressive.iterations).at_least(1)
            .doc("Progressive: photon passes, each with one visible point per pixel.");
        s.number("alpha", d.progressive.alpha).above(0).below(1)
            .doc("Progressive: the fraction of new photons kept (the paper's α).");
        s.number("time_budget", 0).above(0).unit("seconds").derived("none: all iterations")
            .doc("Progressive: stop after the iteration that fills it (gilab render --time-budget sets it).");
        return s;
    }();
    return schema;
}

PhotonMappingSettings PhotonMappingSettings::from(const Settings& s) {
    const SettingsSchema& schema = PhotonMappingSettings::schema();
    PhotonMappingSettings p;
    const std::string& where = s.context();
    p.photons = uint64_t(schema.get<int64_t>(s, "photons"));
    const std::optional<float> radius = schema.get_given<float>(s, "radius");
    p.radius_from_scene = !radius;
    if (radius) p.radius = *radius;
    const std::string gather = schema.get<std::string>(s, "gather");
    p.gather = gather == "knn" ? GatherMode::Knn : GatherMode::Radius;
    p.k = schema.get<int>(s, "k");
    const std::string map = schema.get<std::string>(s, "photon_map");
    p.photon_map = parse_photon_map_kind(map, where + ": setting 'photon_map'");
    p.hash_query = parse_hash_query(schema.get<std::string>(s, "hash_query"), where + ": setting 'hash_query'");
    const std::string pass = schema.get<std::string>(s, "pass");
    p.split = pass == "split";
    const std::string storage = schema.get<std::string>(s, "photon_storage");
    p.storage = storage == "every_hit" ? PhotonStorage::EveryHit : PhotonStorage::Indirect;
    p.tile_shared = parse_tile_share(schema.get<std::string>(s, "tile_shared"), where);
    p.share_tile = schema.get<int>(s, "share_tile");
    const std::optional<std::string> order = schema.get_given<std::string>(s, "gather_order");
    p.gather_by_tiles = order ? *order == "tiles" : p.tile_shared == TileShare::Paper;
    p.seed = uint64_t(schema.get<int64_t>(s, "seed"));
    p.light_samples = schema.get<int>(s, "light_samples");
    p.max_photon_depth = schema.get<int>(s, "max_photon_depth");
    p.tile_size = schema.get<int>(s, "tile_size");
    p.sampling.spp = schema.get<int>(s, "spp");
    // Jittered by default only with several samples: one sample stays at the pixel centre,
    // the image of the one-ray-per-pixel technique.
    p.sampling.jitter = schema.get_given<bool>(s, "jitter").value_or(p.sampling.spp > 1);
    p.stereo.enabled = schema.get<bool>(s, "stereo_reuse");
    p.stereo.match = schema.get<std::string>(s, "stereo_match") == "strict" ? StereoMatch::Strict : StereoMatch::Nearest;
    p.stereo.tolerance = schema.get<float>(s, "stereo_tolerance");
    p.stereo.reshade = schema.get<bool>(s, "stereo_reshade");
    p.stereo.fill = schema.get<bool>(s, "stereo_fill");
    p.foveation.enabled = schema.get<bool>(s, "foveated");
    p.foveation.fovea_degrees = schema.get<float>(s, "fovea_angle");
    p.foveation.periphery_photon_stride = schema.get<int>(s, "periphery_photon_stride");
    p.foveation.gaze_yaw_degrees = schema.get<float>(s, "gaze_yaw");
    p.foveation.gaze_pitch_degrees = schema.get<float>(s, "gaze_pitch");
    p.progressive.enabled = schema.get<bool>(s, "progressive");
    p.progressive.iterations = schema.get<int>(s, "iterations");
    p.progressive.alpha = schema.get<double>(s, "alpha");
    p.progressive.time_budget = schema.get_given<double>(s, "time_budget");

    // The least a map can hold is about one stored copy per emitted photon (a closed
    // scene stores at least that): its record and its structure-of-arrays copy. A count
    // that cannot fit is refused before any photon is traced.
    constexpr uint64_t kBytesPerStoredPhoton = sizeof(Photon) + 10 * sizeof(float);
    MemoryBudget::check(MemoryBudget::times(p.photons, kBytesPerStoredPhoton),
                        "setting 'photons' = " + std::to_string(p.photons) + " (about " +
                            std::to_string(kBytesPerStoredPhoton) + " B per stored photon, one per emitted photon at least)",
                        where);
    const bool shared = p.tile_shared != TileShare::Off;
    if (shared && p.photon_map != PhotonMapKind::HashGrid)
        throw Error(where, "setting 'tile_shared' needs photon_map=hash_grid (it shares hash-grid cells), got " + map);
    if (order && !p.split)
        throw Error(where, "setting 'gather_order' orders the gather pass of pass=split; got pass=" + pass);
    if (p.tile_shared == TileShare::Paper && !p.gather_by_tiles)
        throw Error(where, "setting 'tile_shared=paper' shares per screen tile, so it needs gather_order=tiles");
    if (p.tile_shared == TileShare::CellGroups && p.gather_by_tiles)
        throw Error(where, "setting 'tile_shared=cell_groups' groups hits sorted by cell, so it needs gather_order=cell");
    if ((p.tile_shared == TileShare::Paper || p.gather_by_tiles) && p.tile_size % p.share_tile != 0)
        throw Error(where, "setting 'tile_shared=paper' needs a tile_size that is a multiple of share_tile (share tiles "
                           "nest in render tiles), got tile_size " + std::to_string(p.tile_size) + " and share_tile " +
                               std::to_string(p.share_tile));
    if (p.foveation.enabled) {
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
