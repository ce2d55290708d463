#pragma once
// Every frame of a scene's animation voxelized on one shared grid and merged into one
// time-correlated multi-frame DAG (P2 §4), then laid out for ray casting. The incremental
// build (the streaming mode (b)) hands each frame to the DAG one split cell at a time
// (SequenceVoxelizer): static triangles are kept once, and only the cells a moving
// triangle touches in this frame or the one before are voxelized again, so its peak is
// about the shared DAG plus one batch of cells. The all-at-once build (mode (a))
// voxelizes whole frames, keeps every frame's SVDAG and merges them together at the end.
#include <vector>
#include "accel/temporal/laid_out_multi_frame_dag.hpp"
#include "core/scene/light.hpp"
#include "core/scene/scene.hpp"
#include "core/util/stats.hpp"

namespace gilab {

// How the frames are merged: Incremental is mode (b) above, AllAtOnce mode (a).
enum class DagBuildMode { Incremental, AllAtOnce };
const char* to_string(DagBuildMode mode);  // "incremental", "all_at_once"

struct AnimationDagOptions {
    uint32_t resolution = 256;
    int frames = 1;      // frame k is the scene at time k / fps
    double fps = 30.0;
    DagBuildMode build = DagBuildMode::Incremental;
};

struct AnimationDag {
    LaidOutMultiFrameDag dag;
    std::vector<double> times;                       // scene time of each frame
    std::vector<std::vector<PunctualLight>> lights;  // world-space lights of each frame
    // build_ms (all of it: the bounds pass, voxelizing, merging, laying out),
    // voxelize_ms (incremental: binning and every cell's voxels), merge_ms, layout_ms,
    // voxels_per_frame (mean), voxel_size, table_bytes (the merged DAG's node tables
    // before layout), peak_rss_mib (of the process); incremental only: cells_rebuilt
    // (cells voxelized and merged again, over all frames) and cells_reused (clean cells
    // that took the previous frame's subtree).
    Stats stats;
};

// Throws Error for frames < 1 or fps ≤ 0, and whatever the voxelizer throws (a grid
// whose voxel list would not fit its budget).
AnimationDag build_animation_dag(const Scene& scene, const AnimationDagOptions& options);

}  // namespace gilab
