#include "techniques/dag_raycast/animation_dag.hpp"

#include <string>
#include "accel/multi_frame_dag.hpp"
#include "accel/svdag.hpp"
#include "core/error.hpp"
#include "core/voxelizer.hpp"

namespace gilab {

AnimationDag build_animation_dag(const Scene& scene, const AnimationDagOptions& options) {
    if (options.frames < 1)
        throw Error("dag_raycast", "needs at least one frame, not " + std::to_string(options.frames));
    if (!(options.fps > 0))
        throw Error("dag_raycast", "frame rate must be positive, not " + std::to_string(options.fps));
    Stopwatch total;
    AnimationDag out;
    // One grid for all frames, so a voxel means the same box in every frame and the
    // frames can share subtrees: first pass for the union of the bounds (and the lights).
    Bounds3 bounds;
    for (int k = 0; k < options.frames; ++k) {
        const double t = double(k) / options.fps;
        SceneFrame frame = scene.evaluate(t);
        bounds.extend(frame.bounds);
        out.times.push_back(t);
        out.lights.push_back(std::move(frame.lights));
    }
    const VoxelGrid grid = VoxelGrid::enclosing(bounds, options.resolution);

    double voxelize_ms = 0, merge_ms = 0;
    uint64_t voxels = 0;
    MultiFrameDag merged(grid);
    std::vector<Svdag> per_frame;  // all-at-once only
    for (int k = 0; k < options.frames; ++k) {
        Stopwatch clock;
        std::vector<uint64_t> codes = voxelize(scene.evaluate(out.times[size_t(k)]), grid).codes;
        voxelize_ms += clock.elapsed_ms();
        voxels += codes.size();
        clock.reset();
        if (options.build == DagBuildMode::Incremental)
            merged.append_frame(codes);
        else
            per_frame.push_back(Svdag::from_voxels(grid, codes));
        merge_ms += clock.elapsed_ms();
    }
    if (options.build == DagBuildMode::AllAtOnce) {
        Stopwatch clock;
        merged = MultiFrameDag::merge_all(per_frame);
        per_frame.clear();
        merge_ms += clock.elapsed_ms();
    }
    Stopwatch layout;
    out.dag = merged.lay_out();
    const double layout_ms = layout.elapsed_ms();

    out.stats.set("build_ms", total.elapsed_ms());
    out.stats.set("voxelize_ms", voxelize_ms);
    out.stats.set("merge_ms", merge_ms);
    out.stats.set("layout_ms", layout_ms);
    out.stats.set("voxels_per_frame", double(voxels) / double(options.frames));
    out.stats.set("voxel_size", grid.voxel_size());
    out.stats.set("peak_rss_mib", double(peak_rss_bytes()) / double(1 << 20));
    return out;
}

}  // namespace gilab
