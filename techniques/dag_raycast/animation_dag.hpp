#pragma once
// Every frame of a scene's animation voxelized on one shared grid and merged into one
// time-correlated multi-frame DAG (P2 §4), then laid out for ray casting. Frames are
// voxelized one at a time; the incremental build merges each into the DAG of the frames
// before it and drops its voxels (the streaming mode (b)), the all-at-once build keeps
// every frame's SVDAG and merges them together at the end (mode (a)).
#include <vector>
#include "accel/temporal_svdag.hpp"
#include "core/light.hpp"
#include "core/scene.hpp"
#include "core/stats.hpp"
#include "techniques/dag_raycast/dag_raycast_settings.hpp"

namespace gilab {

struct AnimationDagOptions {
    uint32_t resolution = 256;
    int frames = 1;      // frame k is the scene at time k / fps
    double fps = 30.0;
    DagBuildMode build = DagBuildMode::Incremental;
};

struct AnimationDag {
    TemporalSvdag dag;
    std::vector<double> times;                       // scene time of each frame
    std::vector<std::vector<PunctualLight>> lights;  // world-space lights of each frame
    // build_ms (all of it: the bounds pass, voxelizing, merging, laying out),
    // voxelize_ms, merge_ms, layout_ms, voxels_per_frame (mean), voxel_size,
    // peak_rss_mib (of the process).
    Stats stats;
};

// Throws Error for frames < 1 or fps ≤ 0, and whatever the voxelizer throws (a grid
// whose voxel list would not fit its budget).
AnimationDag build_animation_dag(const Scene& scene, const AnimationDagOptions& options);

}  // namespace gilab
