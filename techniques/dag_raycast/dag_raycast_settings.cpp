#include "techniques/dag_raycast/dag_raycast_settings.hpp"

#include <cmath>
#include <string>
#include "core/util/error.hpp"
#include "core/voxel/voxel_grid.hpp"

namespace gilab {
namespace {

DagShadowSource parse_shadows(const std::string& s) {
    for (DagShadowSource v : {DagShadowSource::Auto, DagShadowSource::ShadowDag, DagShadowSource::DagRay,
                              DagShadowSource::None})
        if (s == to_string(v)) return v;
    throw std::logic_error("dag_raycast: shadows '" + s + "' is declared but not handled");
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

const SettingsSchema& DagRaycastSettings::schema() {
    static const SettingsSchema schema = [] {
        const DagRaycastSettings d;
        SettingsSchema s("dag_raycast", "ray casting through a time-correlated multi-frame DAG (P2 §4)");
        s.integer("resolution", d.resolution).range(2, kMaxVoxelResolution).unit("voxels per axis")
            .doc("One grid shared by all frames.");
        s.integer("frames", d.frames).range(0, 100000)
            .doc("Animation frames in the DAG; 0: the scene's frame count, at most " +
                 std::to_string(kDefaultMaxFrames) + ".");
        s.number("fps", d.fps).at_least(0).unit("frames per second")
            .doc("Frame k shows the scene at k / fps; 0: the scene's frame rate.");
        s.choice("build", to_string(d.build), {"incremental", "all_at_once"})
            .doc("incremental: frame n merged into frames 1..n−1, streamed cell by cell (P2 §4 (b)) | all_at_once: "
                 "per-frame DAGs merged together (P2 §4 (a)).");
        s.integer("light", d.light).at_least(-1)
            .doc("Index of the light; -1: the scene's first point, spot or directional light (none: a headlight).");
        s.number("ambient", d.ambient).range(0, 1).unit("of the light's irradiance").doc("Unshadowed ambient light.");
        s.choice("shadows", to_string(d.shadows), {"auto", "shadow_dag", "dag_ray", "none"})
            .doc("auto = shadow_dag: the frame's shadow DAGs (P2 §3), one over a directional or spot light's light "
                 "space, a cube of six for a point light | dag_ray: a shadow ray through the frame's DAG | none.");
        s.integer("shadow_resolution", d.shadow_resolution).range(0, 131072).unit("voxels per axis")
            .doc("Resolution of each frame's shadow DAG, 8 or more; 0: the voxel resolution.");
        s.integer("tile_size", d.tile_size).range(1, 1024).unit("pixels").doc("Square screen tile of one parallel task.");
        s.integer("seed", int64_t(d.seed)).at_least(0).doc("Recorded only: nothing in this technique is random.");
        s.integer("spp", 1).range(1, 1).unit("samples per pixel").doc("One primary ray per pixel through the frame's root.");
        return s;
    }();
    return schema;
}

DagRaycastSettings DagRaycastSettings::from(const Settings& s) {
    const SettingsSchema& schema = DagRaycastSettings::schema();
    DagRaycastSettings o;
    o.resolution = schema.get<uint32_t>(s, "resolution");
    o.frames = schema.get<int>(s, "frames");
    o.fps = schema.get<double>(s, "fps");
    o.build = schema.get<std::string>(s, "build") == "all_at_once" ? DagBuildMode::AllAtOnce : DagBuildMode::Incremental;
    o.light = schema.get<int>(s, "light");
    o.ambient = schema.get<float>(s, "ambient");
    o.shadows = parse_shadows(schema.get<std::string>(s, "shadows"));
    o.shadow_resolution = schema.get<uint32_t>(s, "shadow_resolution");
    if (o.shadow_resolution != 0 && o.shadow_resolution < 8)
        throw Error(s.context(), "setting 'shadow_resolution' must be 0 (the voxel resolution) or 8 to 131072, got " +
                                     std::to_string(o.shadow_resolution));
    o.tile_size = schema.get<int>(s, "tile_size");
    o.seed = uint64_t(schema.get<int64_t>(s, "seed"));
    (void)schema.get<int>(s, "spp");  // checked: only 1
    return o;
}

}  // namespace gilab
