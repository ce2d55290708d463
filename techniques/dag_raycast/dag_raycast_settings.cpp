#include "techniques/dag_raycast/dag_raycast_settings.hpp"

#include <cmath>
#include <string>
#include "core/util/error.hpp"
#include "core/voxel/voxel_grid.hpp"

namespace gilab {
namespace {

std::string key(const char* name) { return std::string("dag_raycast.") + name; }

DagBuildMode parse_build(const std::string& s) {
    if (s == "incremental") return DagBuildMode::Incremental;
    if (s == "all_at_once") return DagBuildMode::AllAtOnce;
    throw Error(key("build"), "unknown value '" + s + "' (incremental, all_at_once)");
}

DagShadowSource parse_shadows(const std::string& s) {
    for (DagShadowSource v : {DagShadowSource::Auto, DagShadowSource::ShadowDag, DagShadowSource::DagRay,
                              DagShadowSource::None})
        if (s == to_string(v)) return v;
    throw Error(key("shadows"), "unknown value '" + s + "' (auto, shadow_dag, dag_ray, none)");
}

}  // namespace

const char* to_string(DagShadowSource source) {
    switch (source) {
        case DagShadowSource::Auto: return "auto";
        case DagShadowSource::ShadowDag: return "shadow_dag";
        case DagShadowSource::DagRay: return "dag_ray";
        case DagShadowSource::None: return "none";
    }
    return "?";
}

DagRaycastSettings DagRaycastSettings::from(const Settings& s) {
    DagRaycastSettings o;
    const int64_t resolution = s.get<int64_t>("resolution", o.resolution);
    if (resolution < 2 || resolution > int64_t(kMaxVoxelResolution))
        throw Error(key("resolution"),
                    "must be in 2.." + std::to_string(kMaxVoxelResolution) + ", not " + std::to_string(resolution));
    o.resolution = uint32_t(resolution);
    const int64_t frames = s.get<int64_t>("frames", o.frames);
    if (frames < 0 || frames > 100000)
        throw Error(key("frames"), "must be 0 (the scene's, at most 100) or 1..100000, not " + std::to_string(frames));
    o.frames = int(frames);
    o.fps = s.get<double>("fps", o.fps);
    if (!(o.fps >= 0) || !std::isfinite(o.fps))
        throw Error(key("fps"), "must be 0 (the scene's) or a positive frame rate, not " + std::to_string(o.fps));
    o.build = parse_build(s.get<std::string>("build", to_string(o.build)));
    o.light = s.get<int>("light", o.light);
    if (o.light < -1) throw Error(key("light"), "must be -1 (automatic) or a light index");
    o.ambient = s.get<float>("ambient", o.ambient);
    if (!(o.ambient >= 0 && o.ambient <= 1)) throw Error(key("ambient"), "must be in [0, 1]");
    o.shadows = parse_shadows(s.get<std::string>("shadows", to_string(o.shadows)));
    const int64_t shadow_resolution = s.get<int64_t>("shadow_resolution", o.shadow_resolution);
    if (shadow_resolution != 0 && (shadow_resolution < 8 || shadow_resolution > 131072))
        throw Error(key("shadow_resolution"),
                    "must be 0 (the voxel resolution) or in 8..131072, not " + std::to_string(shadow_resolution));
    o.shadow_resolution = uint32_t(shadow_resolution);
    o.tile_size = s.get<int>("tile_size", o.tile_size);
    if (o.tile_size < 1 || o.tile_size > 1024) throw Error(key("tile_size"), "must be in 1..1024");
    // Nothing here is random; the seed every render passes is read so it is not an
    // unknown setting, and recorded in the output.
    const int64_t seed = s.get<int64_t>("seed", int64_t(o.seed));
    if (seed < 0) throw Error(key("seed"), "must be non-negative");
    o.seed = uint64_t(seed);
    const int spp = s.get<int>("spp", 1);
    if (spp != 1)
        throw Error(key("spp"), "the ray caster traces one primary ray per pixel; spp must be 1, not " +
                                    std::to_string(spp));
    return o;
}

}  // namespace gilab
