#pragma once
// Settings of the dag_raycast technique: DagRaycastSettings::schema() declares every key
// with its default, range and description (`gilab list settings dag_raycast`).
#include <cstdint>
#include "accel/temporal/animation_dag.hpp"
#include "core/util/settings.hpp"
#include "core/util/settings_schema.hpp"

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
    // Every key with its default (the members above), range and description.
    static const SettingsSchema& schema();
    // Throws Error naming the key for a bad value.
    static DagRaycastSettings from(const Settings& settings);
};

}  // namespace gilab
