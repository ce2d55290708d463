#include "accel/temporal/animation_dag.hpp"

#include <string>
#include <unordered_map>
#include "accel/temporal/multi_frame_dag.hpp"
#include "accel/temporal/sequence_voxelizer.hpp"
#include "accel/dag/svdag.hpp"
#include "core/util/error.hpp"
#include "core/voxel/voxelizer.hpp"

namespace gilab {
namespace {

struct BuildTimes {
    double voxelize_ms = 0, merge_ms = 0;
    uint64_t voxels = 0;  // summed over frames
    uint64_t cells_rebuilt = 0, cells_reused = 0;
};

// (b) Streaming: each frame goes to the DAG cell by cell, only its dirty cells voxelized.
void build_incremental(const Scene& scene, const std::vector<double>& times, MultiFrameDag& merged,
                       BuildTimes& out) {
    Stopwatch clock;
    SequenceVoxelizer voxelizer(scene, merged.grid(), MultiFrameDag::default_split_level(merged.depth()));
    out.voxelize_ms += clock.elapsed_ms();
    // Voxels per cell as of the latest frame: a clean cell keeps its count.
    std::unordered_map<uint64_t, uint64_t> cell_voxels;
    for (double t : times) {
        clock.reset();
        FrameCells frame = voxelizer.frame_cells(t);
        out.voxelize_ms += clock.elapsed_ms();
        double slice_ms = 0;
        frame.slice = [&, source = std::move(frame.slice)](uint64_t cell) {
            Stopwatch slice_clock;
            std::vector<uint64_t> codes = source(cell);
            cell_voxels[cell] = codes.size();
            slice_ms += slice_clock.elapsed_ms();
            return codes;
        };
        const FrameMergeStats merge = merged.append_frame(frame);
        out.voxelize_ms += slice_ms;
        out.merge_ms += merge.ms - slice_ms;
        out.cells_rebuilt += merge.cells_rebuilt;
        out.cells_reused += merge.cells_reused;
        for (uint64_t cell : frame.cells) out.voxels += cell_voxels[cell];
    }
}

// (a) Every frame's SVDAG kept, then all merged level by level.
void build_all_at_once(const Scene& scene, const std::vector<double>& times, MultiFrameDag& merged,
                       BuildTimes& out) {
    std::vector<Svdag> per_frame;
    for (double t : times) {
        Stopwatch clock;
        std::vector<uint64_t> codes = voxelize(scene.evaluate(t), merged.grid()).codes;
        out.voxelize_ms += clock.elapsed_ms();
        out.voxels += codes.size();
        clock.reset();
        per_frame.push_back(Svdag::from_voxels(merged.grid(), codes));
        out.merge_ms += clock.elapsed_ms();
    }
    Stopwatch clock;
    merged = MultiFrameDag::merge_all(per_frame);
    out.merge_ms += clock.elapsed_ms();
}

}  // namespace

const char* to_string(DagBuildMode mode) {
    return mode == DagBuildMode::Incremental ? "incremental" : "all_at_once";
}

AnimationDag build_animation_dag(const Scene& scene, const AnimationDagOptions& options) {
    if (options.frames < 1)
        throw Error("dag_raycast", "needs at least one frame, not " + std::to_string(options.frames));
    if (!(options.fps > 0))
        throw Error("dag_raycast", "frame rate must be positive, not " + std::to_string(options.fps));
    Stopwatch total;
    AnimationDag out;
    for (int k = 0; k < options.frames; ++k) out.times.push_back(double(k) / options.fps);
    // One grid for all frames, so a voxel means the same box in every frame and the frames
    // can share subtrees: the union of every frame's bounds (static nodes flattened once).
    const VoxelGrid grid = VoxelGrid::enclosing(sequence_bounds(scene, out.times, &out.lights), options.resolution);

    BuildTimes times;
    MultiFrameDag merged(grid);
    if (options.build == DagBuildMode::Incremental)
        build_incremental(scene, out.times, merged, times);
    else
        build_all_at_once(scene, out.times, merged, times);
    const size_t table_bytes = merged.table_bytes();
    Stopwatch layout;
    out.dag = merged.lay_out();
    const double layout_ms = layout.elapsed_ms();

    out.stats.set("build_ms", total.elapsed_ms());
    out.stats.set("voxelize_ms", times.voxelize_ms);
    out.stats.set("merge_ms", times.merge_ms);
    out.stats.set("layout_ms", layout_ms);
    out.stats.set("voxels_per_frame", double(times.voxels) / double(options.frames));
    out.stats.set("voxel_size", grid.voxel_size());
    out.stats.set("table_bytes", double(table_bytes));
    if (options.build == DagBuildMode::Incremental) {
        out.stats.set("cells_rebuilt", double(times.cells_rebuilt));
        out.stats.set("cells_reused", double(times.cells_reused));
    }
    out.stats.set("peak_rss_mib", double(peak_rss_bytes()) / double(1 << 20));
    return out;
}

}  // namespace gilab
