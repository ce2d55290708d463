#pragma once
// Settings of the dag_raycast technique, read from a Settings dictionary. Every key is
// checked; keys it does not read are reported by the caller.
//
// resolution (256: voxels per axis of the one grid shared by all frames), frames (0: the
// scene's animation frame count, capped at 100), fps (0: the scene's frame rate; frame k
// shows the scene at k / fps), build (incremental | all_at_once: how the frames are merged,
// P2 §4 (b) / (a)), light (-1: the scene's first point or directional light, else its
// index), ambient (0.05: unshadowed light as a fraction of the light's irradiance),
// shadows (auto = shadow_dag | dag_ray | none: shadow_dag looks up the frame's shadow
// DAGs, one over a directional or spot light's light space or a cube of six for a point
// light; dag_ray casts a shadow ray through the frame's DAG), shadow_resolution (0: the voxel resolution; voxels per
// axis of each frame's shadow DAG), tile_size (16: image tile), seed (recorded only: nothing is random), spp (only 1: one
// primary ray per pixel).
#include <cstdint>
#include "accel/temporal/animation_dag.hpp"
#include "core/util/settings.hpp"

namespace gilab {

// Where a lit surface's visibility comes from.
enum class DagShadowSource {
    Auto,       // ShadowDag
    ShadowDag,  // the frame's shadow DAGs (P2 §3; six for a point light), built at prepare
    DagRay,     // a shadow ray through the frame's own multi-frame DAG root
    None,       // every surface facing the light is lit
};
const char* to_string(DagShadowSource source);

struct DagRaycastSettings {
    uint32_t resolution = 256;
    int frames = 0;
    double fps = 0;
    DagBuildMode build = DagBuildMode::Incremental;
    int light = -1;
    float ambient = 0.05f;
    DagShadowSource shadows = DagShadowSource::Auto;
    uint32_t shadow_resolution = 0;
    int tile_size = 16;
    uint64_t seed = 1;

    static constexpr int kDefaultMaxFrames = 100;
    // Throws Error naming the key ("dag_raycast.<key>") for a bad value.
    static DagRaycastSettings from(const Settings& settings);
};

}  // namespace gilab
