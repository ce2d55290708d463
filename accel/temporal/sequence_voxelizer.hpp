#pragma once
// Streams the frames of an animation into MultiFrameDag::append_frame one split cell at a
// time (P2 §4 build mode (b)). Nodes that never move are evaluated once and kept as bare
// world positions and triangles, binned into the split cells; each frame evaluates only
// the moving nodes and bins their triangles. A cell's voxels come from a Voxelizer over
// that cell's triangles alone (a crowded cell's a few thousand at a time), so no whole-frame
// voxel list, prepared-triangle array or scene frame is ever held: memory is the static
// triangles, one frame's moving triangles and one batch of cells. Cells that no moving
// triangle touched in this frame or the one before are clean: their voxels are the
// previous frame's.
#include <cstdint>
#include <memory>
#include <span>
#include <vector>
#include "accel/temporal/multi_frame_dag.hpp"
#include "core/scene/scene.hpp"
#include "core/voxel/voxel_grid.hpp"
#include "core/voxel/voxelizer.hpp"

namespace gilab {

// The union of the scene's bounds at `times` — what flattening whole frames would give —
// with the static nodes flattened once and only the moving ones per time, a few nodes at
// a time. If `lights` is given, it receives each time's world-space lights.
Bounds3 sequence_bounds(const Scene& scene, std::span<const double> times,
                        std::vector<std::vector<PunctualLight>>* lights = nullptr);

class SequenceVoxelizer {
public:
    // The scene must outlive this object. Throws Error for a bad grid, a split level
    // outside 0..grid depth, or static geometry with non-finite positions.
    SequenceVoxelizer(const Scene& scene, const VoxelGrid& grid, int split_level, VoxelizeOptions options = {});
    ~SequenceVoxelizer();
    SequenceVoxelizer(const SequenceVoxelizer&) = delete;
    SequenceVoxelizer& operator=(const SequenceVoxelizer&) = delete;

    // The scene at `time`, cell by cell. `dirty` is relative to the frame of the previous
    // call (every cell on the first), so call it in frame order, as frames are appended.
    // The returned slice refers to this object, which must outlive it; slice may be
    // called for any cell, in any order, from one thread at a time.
    FrameCells frame_cells(double time);

    const VoxelGrid& grid() const { return grid_; }
    int split_level() const { return split_level_; }
    size_t static_triangle_count() const;
    size_t static_bytes() const;  // static positions, triangles and their cell bins

    // Cells voxelized together in parallel by one slice call; the ones not asked for yet
    // wait in a cache until they are.
    static constexpr size_t kBatchCells = 48;

private:
    struct TriangleSet;
    struct CellBins;
    struct FrameState;
    std::vector<uint64_t> voxelize_cell(uint64_t cell, const FrameState& frame) const;
    std::vector<uint64_t> slice(uint64_t cell, FrameState& frame) const;

    VoxelGrid grid_;
    int split_level_ = 0;
    int cell_log2_ = 0;  // voxels per cell side = 2^cell_log2_
    VoxelizeOptions options_;
    const Scene& scene_;
    std::vector<bool> dynamic_nodes_;
    std::unique_ptr<TriangleSet> static_triangles_;
    std::unique_ptr<CellBins> static_bins_;
    std::vector<uint64_t> previous_dynamic_cells_;
    bool first_frame_ = true;
};

}  // namespace gilab
